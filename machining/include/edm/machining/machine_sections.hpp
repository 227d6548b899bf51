#pragma once
// The one reader of the machine-config sections that part programs are checked against:
// `machine.axes` (soft limits) and `conditions` (the E-number table), DESIGN §8. The runtime's
// config parser and machining's read_machine_tables() (edmhmi check) both call these, so both
// accept the same documents, fill the same defaults and report the same file:line:col messages.
// Needs yaml-cpp (see located_yaml.hpp). Non-RT (allocates); thread-compatible.

#include <vector>

#include "edm/machining/located_yaml.hpp"
#include "edm/machining/machine_tables.hpp"

namespace edm::machining {

/// Reads the list under `machine.axes`: keys, types, ranges (max_mm > min_mm, positive dynamics)
/// and duplicate axis names, each problem reported to `r`. Returns every entry read (entries
/// with errors included; the caller throws when `r`'s sink is not empty).
std::vector<LocatedAxis> read_axes(yaml::Reader& r, const yaml::Value& axes);
/// `machine.kind`: drill (the default), wire or sink; another name is an error at its place.
MachineKind read_machine_kind(yaml::Reader& r, const yaml::Value& v);

/// Reads the list under `conditions`: keys, types, ranges and duplicate E numbers, as above.
std::vector<LocatedCondition> read_conditions(yaml::Reader& r, const yaml::Value& conditions);

}  // namespace edm::machining
