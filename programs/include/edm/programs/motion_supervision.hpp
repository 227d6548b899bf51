#pragma once
// MotionSupervision: the job sequencer's checks of the motion, kept apart so that the runtime's
// safety supervisor can take them over (issue 19) without touching the sequencing:
//  - soft limits: the actual X/Y/Z against the config's axis limits (±1 nm); outside → alarm 141
//    (kSoftLimit, fault → safe state), raised once per excursion;
//  - following error: a position loop's following-error fault → alarm 140 (kFollowingError).
// RT-safety: check_*() are RT-safe (Machine::raise is). Not thread-safe: the owning task.

#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::programs {

class MotionSupervision {
 public:
  /// Load time. `source` names the alarms' source and must outlive this object.
  void configure(rt::Machine* machine, const machining::MachineTables* tables,
                 const char* source) noexcept {
    machine_ = machine;
    tables_ = tables;
    source_ = source;
  }
  void reset() noexcept { limit_alarm_raised_ = false; }
  void check_limits(rt::TimePoint now, double x, double y, double z) noexcept;
  void check_following_error(rt::TimePoint now, bool fault) noexcept;

 private:
  rt::Machine* machine_{nullptr};
  const machining::MachineTables* tables_{nullptr};
  const char* source_{""};
  bool limit_alarm_raised_{false};
};

}  // namespace edm::programs
