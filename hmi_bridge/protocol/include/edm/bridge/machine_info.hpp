#pragma once
// The `machine.info` reply (docs/protocol.md): the machine's name, soft limits and machining
// conditions — the tables the runtime checks programs against. edmhmi interprets a part program
// with these, so its wear pre-compensation (eq. 9-11) and its checks use the very numbers of the
// machine it is about to run on, not a config file that may differ.
//
//   {"name": "drill-sim",
//    "axes": [{"name": "X", "min_mm": -100, "max_mm": 100, "v_max_mm_s": 30, "a_max_mm_s2": 2000}],
//    "conditions": [{"E": 1, "name": "drill-rough", "polarity": "negative",
//                    "open_voltage_v": 100, "peak_current_a": 15, "on_time_us": 20,
//                    "off_time_us": 10, "tdr_us": 8, "servo_ref_v": 40, "wear_ratio": 0.62}]}
//
// Thread-safety: pure functions. Not RT-safe (allocates).

#include <string>

#include "edm/bridge/codec.hpp"
#include "edm/machining/machine_tables.hpp"

namespace edm::bridge {

Json to_json(const machining::MachineTables& tables, const std::string& machine_name);

/// Decodes a machine.info body. On failure returns false and names the bad field in `error`
/// (missing or mistyped fields, non-finite numbers, an unknown axis or polarity, E < 1,
/// duplicate E numbers or axes, min_mm > max_mm).
bool from_json(const Json& j, machining::MachineTables& out, std::string& machine_name,
               std::string& error);

}  // namespace edm::bridge
