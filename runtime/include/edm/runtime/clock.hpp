#pragma once
// Clocks: the real clock (CLOCK_MONOTONIC + clock_nanosleep(TIMER_ABSTIME)) and the virtual
// clock (deterministic time that only moves when the scheduler or a test advances it).
// Thread-safety: RealClock is thread-safe. VirtualClock is driven by one thread (the virtual
// scheduler); now() may be read from any thread.

#include <atomic>

#include "edm/runtime/time.hpp"

namespace edm::rt {

enum class ClockKind { kReal, kVirtual };

class Clock {
 public:
  virtual ~Clock() = default;
  /// Current time. RT-safe.
  [[nodiscard]] virtual TimePoint now() const noexcept = 0;
  [[nodiscard]] virtual ClockKind kind() const noexcept = 0;
};

/// CLOCK_MONOTONIC. sleep_until() uses clock_nanosleep(TIMER_ABSTIME) so a task stays on its
/// absolute time grid however long the previous cycle took.
class RealClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const noexcept override;
  [[nodiscard]] ClockKind kind() const noexcept override { return ClockKind::kReal; }
  /// Sleeps until the absolute time t (restarts after signals). RT-safe.
  static void sleep_until(TimePoint t) noexcept;
};

/// Deterministic time. The virtual scheduler sets it to each release time; a test (or a block
/// modelling execution cost) may advance it inside a cycle to inject execution time.
class VirtualClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const noexcept override {
    return TimePoint{now_ns_.load(std::memory_order_acquire)};
  }
  [[nodiscard]] ClockKind kind() const noexcept override { return ClockKind::kVirtual; }
  /// Moves time forward to t; time never goes backwards (an earlier t is ignored).
  void advance_to(TimePoint t) noexcept;
  /// Moves time forward by d (e.g. to charge execution time to the running cycle).
  void advance(Duration d) noexcept { advance_to(now() + d); }

 private:
  std::atomic<std::int64_t> now_ns_{0};
};

}  // namespace edm::rt
