#pragma once
// Schedulers: when each task's run_cycle() is called.
//
// RealTimeScheduler — one thread per task, released on the absolute grid
//   T0 + k·interval with clock_nanosleep(TIMER_ABSTIME). Each thread sets itself up with
//   setup_task_thread() (SCHED_FIFO 90 − priority when the process may use it, else
//   SCHED_OTHER; optional CPU affinity; stack pre-faulted) and the controlling thread reports
//   the result (thread_setups(), RtEnvironment); the PM QoS request and mlockall are
//   RtEnvironment's.
// VirtualScheduler — one thread, deterministic: the task with the earliest release runs next,
//   ties broken by priority (0 first), then by task order. A cycle executes atomically at its
//   release time (no preemption in virtual time); execution time is zero unless a block charges
//   time to the VirtualClock, in which case later releases start late (latency) and overrun
//   rules apply exactly as on the real clock.
//
// Thread-safety: start()/stop()/run_until() from one controlling thread.

#include <atomic>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/rt_environment.hpp"
#include "edm/runtime/task.hpp"

namespace edm::rt {

class RealTimeScheduler {
 public:
  RealTimeScheduler() = default;
  ~RealTimeScheduler() { stop(); }
  RealTimeScheduler(const RealTimeScheduler&) = delete;
  RealTimeScheduler& operator=(const RealTimeScheduler&) = delete;

  /// Starts one thread per task; all grids start at the same T0 (now + lead time), chosen once
  /// every thread is ready. With run_for, each task runs exactly the releases in
  /// [T0, T0 + run_for) and then its thread ends. Throws std::runtime_error if a CPU is not
  /// available.
  void start(const std::vector<Task*>& tasks, const RealClock& clock,
             std::optional<Duration> run_for = std::nullopt);
  /// The common origin T0 (valid once start() has returned).
  [[nodiscard]] TimePoint origin() const noexcept { return TimePoint{t0_ns_.load()}; }
  /// T0 + run_for, or the far future without run_for.
  [[nodiscard]] TimePoint end() const noexcept { return TimePoint{end_ns_.load()}; }
  /// Asks every task thread to finish its current cycle, then joins them. Idempotent.
  void stop();
  /// True if any task fell back from SCHED_FIFO to SCHED_OTHER.
  [[nodiscard]] bool degraded() const noexcept { return degraded_.load(); }
  /// What each task thread set up for itself, in task order (valid once start() has returned).
  [[nodiscard]] const std::vector<ThreadSetup>& thread_setups() const noexcept { return setups_; }

 private:
  void task_main(Task& task, std::size_t index) noexcept;

  const RealClock* clock_{nullptr};
  std::vector<std::thread> threads_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> degraded_{false};
  std::vector<ThreadSetup> setups_;     // slot i written by thread i before it counts as ready
  std::atomic<std::size_t> ready_{0};   // threads set up and waiting for the origin
  std::atomic<std::int64_t> t0_ns_{0};  // the common origin; 0 until every thread is ready
  std::atomic<std::int64_t> end_ns_{std::numeric_limits<std::int64_t>::max()};
};

class VirtualScheduler {
 public:
  /// Tasks all start their grid at the clock's current time.
  VirtualScheduler(std::vector<Task*> tasks, VirtualClock& clock);

  /// Runs cycles whose release is < end (virtual time), then sets the clock to end. Calls
  /// between_cycles (if set) after every cycle; stops early when *stop becomes true.
  void run_until(TimePoint end, const std::function<void()>& between_cycles = {},
                 const std::atomic<bool>* stop = nullptr);

  [[nodiscard]] TimePoint next_release(std::size_t task_index) const { return next_[task_index]; }

 private:
  std::vector<Task*> tasks_;
  std::vector<TimePoint> next_;
  VirtualClock* clock_;
};

}  // namespace edm::rt
