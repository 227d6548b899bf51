#pragma once
// A task: an IEC 61131-3 cyclic task — interval, priority, watchdog, overrun policy and an
// ordered list of programs. run_cycle() is one scan:
//   apply queued parameter writes → safe-state hooks if the machine just entered FAULT/ESTOP →
//   release every force while in FAULT/ESTOP (the safe state wins at the output latch) →
//   latch inputs (I/O task only) → programs in order → safety supervisor (I/O task only: it
//   refuses commands and holds the safe state at the output latch) → publish outputs (I/O task
//   only) → trace sample → statistics → watchdog (a host stall — the cycle over its watchdog
//   time while its own CPU time was within it — is counted, raised as warning alarm 102 and, with
//   `host_stall: tolerate`, not held against the watchdog).
// The schedulers (scheduler.hpp) decide when run_cycle() is called.
//
// Thread-safety: run_cycle() runs on the task's own thread only. post_param_write() may be
// called from any non-RT thread. stats() may be read from any thread.

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <mutex>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/cycle_observer.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/program.hpp"
#include "edm/runtime/task_stats.hpp"
#include "edm/runtime/watchdog.hpp"

namespace edm::rt {

class Supervisor;
class TraceRecorder;
class VariableRegistry;

/// A runtime parameter write, validated on the non-RT side, applied at the next cycle start.
struct ParamWrite {
  Block* block{nullptr};
  std::uint32_t index{0};
  ParamValue value{};
};

class Task {
 public:
  static constexpr std::size_t kParamQueueCapacity = 64;

  Task(TaskSpec spec, Machine& machine);
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  // Build-time wiring (non-RT).
  void add_program(Program& p) { programs_.push_back(&p); }
  void attach_driver(IoDriver& d) { driver_ = &d; }
  void attach_trace(TraceRecorder& t, std::uint32_t channel) {
    trace_ = &t;
    trace_channel_ = channel;
  }
  /// Adds an end-of-cycle observer (bridge status/trace tap). Non-RT, before the task runs; the
  /// observer must outlive the task's run.
  void add_observer(CycleObserver& o) { observers_.push_back(&o); }
  /// Stops sampling the trace (no --trace-out: nothing would drain the ring). Non-RT, before run.
  void detach_trace() noexcept { trace_ = nullptr; }
  /// The registry whose forces this task releases in FAULT/ESTOP. Non-RT, before run.
  void attach_forces(VariableRegistry& r) noexcept { forces_ = &r; }
  /// The safety supervisor, run after the programs and before the driver publishes the
  /// outputs (the I/O task only). Non-RT, before run; it must outlive the task's run.
  void attach_supervisor(Supervisor& s) noexcept { supervisor_ = &s; }

  /// One scan for the cycle scheduled at `release`. Returns the time the cycle ended. RT-safe.
  TimePoint run_cycle(TimePoint release, const Clock& clock) noexcept;

  /// Queues a validated parameter write for the next cycle. Thread-safe (non-RT callers).
  /// False if the queue is full.
  bool post_param_write(const ParamWrite& w);
  /// Applies queued writes now. Used only while the task is not running. Non-RT.
  void apply_pending_param_writes() noexcept;

  [[nodiscard]] const TaskSpec& spec() const noexcept { return spec_; }
  [[nodiscard]] const std::string& name() const noexcept { return spec_.name; }
  [[nodiscard]] TaskStats& stats() noexcept { return stats_; }
  [[nodiscard]] const TaskStats& stats() const noexcept { return stats_; }
  [[nodiscard]] IoDriver* driver() const noexcept { return driver_; }
  [[nodiscard]] const std::vector<Program*>& programs() const noexcept { return programs_; }
  [[nodiscard]] std::uint64_t cycles() const noexcept {
    return cycle_.load(std::memory_order_relaxed);
  }
  /// Watchdog trips with action warn (faults show up as machine state and alarms).
  [[nodiscard]] std::uint64_t watchdog_warnings() const noexcept {
    return watchdog_warnings_.load(std::memory_order_relaxed);
  }
  /// Cycles over the watchdog time that were host stalls (see run_cycle), whatever the policy.
  [[nodiscard]] std::uint64_t host_stalls() const noexcept {
    return host_stalls_.load(std::memory_order_relaxed);
  }
  /// The longest of them (its execution time, wall clock).
  [[nodiscard]] Duration longest_host_stall() const noexcept {
    return Duration{longest_stall_ns_.load(std::memory_order_relaxed)};
  }
  /// Puts this task's programs and driver into the safe state now (orderly shutdown). Only
  /// while the task thread is not running.
  void enter_safe_state_now(const SafeStateRequest& r) noexcept;

 private:
  void on_safe_state(MachineState s) noexcept;
  /// Host-stall check and watchdog for a cycle that ran `exec` (wall clock). RT-safe.
  void judge_cycle(TimePoint release, Duration exec, const Clock& clock,
                   Duration cpu_start) noexcept;

  TaskSpec spec_;
  Machine* machine_;
  std::vector<Program*> programs_;
  IoDriver* driver_{nullptr};
  TraceRecorder* trace_{nullptr};
  std::uint32_t trace_channel_{0};
  VariableRegistry* forces_{nullptr};
  Supervisor* supervisor_{nullptr};
  std::vector<CycleObserver*> observers_;
  TaskStats stats_;
  Watchdog watchdog_;
  std::atomic<std::uint64_t> cycle_{0};
  std::atomic<std::uint64_t> watchdog_warnings_{0};
  std::atomic<std::uint64_t> host_stalls_{0};
  std::atomic<std::int64_t> longest_stall_ns_{0};
  std::uint64_t seen_safe_epoch_{0};
  bool driver_faulted_{false};
  bool watchdog_tripped_{false};
  bool stall_latched_{false};
  double dt_s_;

  std::mutex producer_mutex_;  // serialises non-RT producers; the RT consumer never takes it
  boost::lockfree::spsc_queue<ParamWrite, boost::lockfree::capacity<kParamQueueCapacity>>
      param_writes_;
};

}  // namespace edm::rt
