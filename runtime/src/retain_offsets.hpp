#pragma once
// The work offsets G54…G59 the runtime retains beside the job record (DESIGN §11: "retained
// data (electrode length left, counters, work offsets)"). Entries `offsets.G54.x` … `G59.z`:
// names no config variable can have. Retained whenever the config has a retain file.
//
// RT-safety: none of this runs on an RT thread (the offsets are non-RT data).

#include <vector>

#include "edm/runtime/retain.hpp"
#include "edm/runtime/work_offsets.hpp"

namespace edm::rt::retain_offsets {

/// The 18 variables, reading `offsets` live; `offsets` must outlive the store.
[[nodiscard]] std::vector<RetainStore::Variable> variables(const WorkOffsets& offsets);

/// Removes the `offsets.*` entries from `values` and sets `offsets` from those of the right type
/// and a finite value (others are ignored). Returns how many it set.
int take(RetainMap& values, WorkOffsets& offsets);

}  // namespace edm::rt::retain_offsets
