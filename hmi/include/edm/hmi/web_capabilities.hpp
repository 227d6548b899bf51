#pragma once
// Which operator functions (DESIGN §12, issue 21: reference, jog, touch-off, work offsets, MDI,
// run from a block, feed override) the connected edmplc offers, so the page shows their panels
// only when they work (docs/web.md "What is supported").
//
// Two sources, in order:
//  1. a capability list in machine.info (`"ops": ["home", "jog", …]`) when the runtime sends one;
//  2. otherwise a probe that cannot act: each op name is sent on a fresh TCP connection *before*
//     any hello. edmplc answers `unknown_op` for an op it does not have and `unauthorized`
//     ("hello first") for one it has — an unauthenticated session can run nothing.
// The op names are the ones proposed for issue 21; kOperatorFunctions is the one place to align
// them with what issue 21 ships.
//
// Non-RT. probe_ops() blocks up to `timeout` (its own io_context): call it off the I/O thread.
// Pure otherwise (thread-safe).

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "edm/bridge/codec.hpp"

namespace edm::hmi {

struct OperatorFunction {
  std::string_view
      key;              // the page's panel: reference, jog, touch, offsets, mdi, run_from, override
  std::string_view op;  // the bridge op that panel needs
};
inline constexpr std::array<OperatorFunction, 7> kOperatorFunctions{{
    {"reference", "home"},
    {"jog", "jog"},
    {"touch", "touch"},
    {"offsets", "offset.set"},
    {"mdi", "mdi"},
    {"run_from", "cycle.start_from"},
    {"override", "feed.override"},
}};

/// The ops of `ops` that the bridge at host:port knows (probe 2 above). Throws std::runtime_error
/// when it cannot connect or a reply does not come within `timeout`.
std::vector<std::string> probe_ops(const std::string& host, std::uint16_t port,
                                   const std::vector<std::string>& ops,
                                   std::chrono::milliseconds timeout);

/// {"source": "machine.info" | "probe" | "none", "reference": bool, "jog": bool, …,
///  "work_coordinates": bool (offsets present)} from machine.info's "ops" when present, else
/// from `probed` (the ops probe_ops() found).
bridge::Json capabilities_json(const bridge::Json& machine_info,
                               const std::vector<std::string>* probed);

}  // namespace edm::hmi
