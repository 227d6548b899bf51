#pragma once
// A hook at the end of a task's cycle, for non-RT consumers that need a consistent per-cycle view
// (the bridge's status snapshot and trace tap). The observer runs on the task's RT thread, after
// outputs are published and the trace sampled, before the statistics are recorded.
//
// RT-safety: on_cycle_end() must not allocate, lock, log or block — publish through lock-free
// structures only (seqlock, SPSC ring). Observers are attached before the tasks run.

#include "edm/runtime/block.hpp"

namespace edm::rt {

class CycleObserver {
 public:
  virtual ~CycleObserver() = default;
  /// Called once per cycle on the task's thread. RT-safe implementations only.
  virtual void on_cycle_end(const CycleContext& ctx) noexcept = 0;
};

}  // namespace edm::rt
