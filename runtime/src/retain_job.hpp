#pragma once
// The job record the runtime retains beside the configured variables, so that a restart after an
// unclean stop (kill -9, power loss) knows which job was running (DESIGN §11; docs/runtime.md,
// "Restart after an unclean stop"). Entries `job.running`, `job.program`, `job.block`,
// `job.blocks`, `job.line` and, with `retain.job_depth`, `job.depth_mm`: two-part names no config
// variable can have (those are `io.<pin>` or at least `program.block.pin`).
//
// RT-safety: none of this runs on an RT thread. The read functions run on the retain store's
// thread and only load the JobStore's atomics (and the depth variable's), so the cycle is
// untouched: no allocation, lock or system call is added to it.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "edm/runtime/job.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::rt::retain_job {

/// The record's measured quantities (each empty: no such entry): `retain.job_depth`,
/// `retain.job_touch_z`, `retain.job_wear`.
struct Readers {
  std::function<double()> depth, touch_z, wear;
};

/// The record's variables, reading `job` live and the readers (entries `job.depth_mm`,
/// `job.touch_z_mm`, `job.wear_mm`). While no job has begun in this runtime, they keep reporting
/// `kept` (the interrupted job found at start), so a second unclean stop before the next job still
/// names it. `job.running` is urgent: its change is written without waiting for min_interval. `job`
/// and `kept` must outlive the store.
[[nodiscard]] std::vector<RetainStore::Variable> variables(
    const JobStore& job, const std::optional<InterruptedJob>& kept, Readers readers);

/// Removes the `job.*` entries from `values` (so they are not restored as variables) and returns
/// the job they describe when `job.running` was true; nullopt otherwise (no record, a finished or
/// aborted job, a record of the wrong types).
[[nodiscard]] std::optional<InterruptedJob> take(RetainMap& values);

/// Alarm 182's text: program, block, line and depth.
[[nodiscard]] std::string alarm_text(const InterruptedJob& j);

}  // namespace edm::rt::retain_job
