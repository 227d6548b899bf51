#pragma once
// The work offsets G54…G59 and the electrode length they refer to, retained beside the job
// record (DESIGN §11: "retained data (electrode length left, counters, work offsets)"). Entries
// `offsets.G54.x` … `offsets.G59.z`, `offsets.G54.z_electrode_mm` … (the electrode length each
// frame's Z was set with) and `electrode.length_mm` (the estimate now): names no config variable
// can have. Retained whenever the config has a retain file; a file without the electrode entries
// (written before issue 33) loads with them unknown (0).
//
// RT-safety: none of this runs on an RT thread (the store samples the electrode's atomic).

#include <vector>

#include "edm/runtime/electrode.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/work_offsets.hpp"

namespace edm::rt::retain_offsets {

/// The 25 variables, reading `offsets` and `electrode` live; both must outlive the store.
[[nodiscard]] std::vector<RetainStore::Variable> variables(const WorkOffsets& offsets,
                                                           const Electrode& electrode);

/// Removes the `offsets.*` and `electrode.*` entries from `values` and sets `offsets` and
/// `electrode` from those of the right type and a finite value (others are ignored). Returns how
/// many it set.
int take(RetainMap& values, WorkOffsets& offsets, Electrode& electrode);

}  // namespace edm::rt::retain_offsets
