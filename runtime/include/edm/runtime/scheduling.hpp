#pragma once
// The release-time arithmetic shared by the real and the virtual scheduler.
// Pure functions; RT-safe and thread-safe.

#include <cstdint>

#include "edm/runtime/config.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

struct NextRelease {
  TimePoint release{};       // when the next cycle is due
  bool overrun{false};       // the cycle ended after the next grid slot had started
  std::uint64_t omitted{0};  // grid slots that get no cycle at all
};

/// Given a cycle scheduled at `release` that ended at `end`, the next release on the grid
/// release + k·interval:
///  - no overrun (end <= release + interval): release + interval;
///  - skip: the first grid slot after `end`; every slot that passed during the cycle is omitted;
///  - asap: the latest slot that passed is run at once (late), older passed slots are omitted.
/// Example, interval 1 ms, cycle at 0 ending at 3.5 ms: skip → next 4 ms, 3 omitted;
/// asap → next 3 ms (starts immediately, 0.5 ms late), 2 omitted.
constexpr NextRelease next_release(TimePoint release, TimePoint end, Duration interval,
                                   OverrunPolicy policy) noexcept {
  const TimePoint next = release + interval;
  if (end <= next) {
    return {next, false, 0};
  }
  // Grid slots m >= 1 with release + m·interval < end have passed: m = 1..passed.
  const std::int64_t span = (end - release).count();
  const std::int64_t step = interval.count();
  const auto passed = static_cast<std::uint64_t>((span + step - 1) / step - 1);
  if (policy == OverrunPolicy::kSkip) {
    return {release + interval * static_cast<std::int64_t>(passed + 1), true, passed};
  }
  return {release + interval * static_cast<std::int64_t>(passed), true, passed - 1};
}

/// SCHED_FIFO priority for a task priority (0 = highest): 90 − priority, at least 1.
/// 90 leaves room above for the kernel's own threaded IRQs and watchdogs at 91..99.
constexpr int fifo_priority(int task_priority) noexcept {
  const int p = 90 - task_priority;
  return p < 1 ? 1 : p;
}

}  // namespace edm::rt
