#pragma once
// Clocks: the real clock (CLOCK_MONOTONIC + clock_nanosleep(TIMER_ABSTIME)) and the virtual
// clock (deterministic time that only moves when the scheduler or a test advances it). Each also
// gives the CPU time of the calling thread, which tells a cycle that really overran (its own work
// took the time) from a host stall (the thread was descheduled: wall time passed, CPU time did
// not).
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
  /// CPU time the calling thread has run so far (only differences are meaningful). RT-safe.
  [[nodiscard]] virtual Duration thread_cpu_time() const noexcept = 0;
};

/// CLOCK_MONOTONIC. sleep_until() uses clock_nanosleep(TIMER_ABSTIME) so a task stays on its
/// absolute time grid however long the previous cycle took.
class RealClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const noexcept override;
  [[nodiscard]] ClockKind kind() const noexcept override { return ClockKind::kReal; }
  /// CLOCK_THREAD_CPUTIME_ID: excludes the time the thread was preempted and, on a guest with
  /// steal-time accounting, the time the hypervisor did not run its vCPU. A system call (~0.3 µs).
  [[nodiscard]] Duration thread_cpu_time() const noexcept override;
  /// Sleeps until the absolute time t (restarts after signals). RT-safe.
  static void sleep_until(TimePoint t) noexcept;
};

/// Deterministic time. The virtual scheduler sets it to each release time; a test (or a block
/// modelling execution cost) may advance it inside a cycle to inject execution time, or stall it
/// to inject a host stall.
class VirtualClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const noexcept override {
    return TimePoint{now_ns_.load(std::memory_order_acquire)};
  }
  [[nodiscard]] ClockKind kind() const noexcept override { return ClockKind::kVirtual; }
  /// The execution time charged by advance() so far (one CPU for the one scheduler thread).
  [[nodiscard]] Duration thread_cpu_time() const noexcept override {
    return Duration{cpu_ns_.load(std::memory_order_acquire)};
  }
  /// Moves time forward to t; time never goes backwards (an earlier t is ignored). Not CPU time:
  /// the scheduler releasing the next cycle.
  void advance_to(TimePoint t) noexcept;
  /// Moves time forward by d and charges it as CPU time (execution time of the running cycle).
  void advance(Duration d) noexcept {
    cpu_ns_.fetch_add(d.count(), std::memory_order_acq_rel);
    advance_to(now() + d);
  }
  /// A host stall of d: time moves forward, CPU time does not (the whole process descheduled).
  void stall(Duration d) noexcept { advance_to(now() + d); }

 private:
  std::atomic<std::int64_t> now_ns_{0};
  std::atomic<std::int64_t> cpu_ns_{0};
};

}  // namespace edm::rt
