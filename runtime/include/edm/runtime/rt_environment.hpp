#pragma once
// The real-time environment the runtime sets up for itself on the real clock (DESIGN §6, §13),
// so that edmplc as shipped gets what a benchmark driver or a wrapper script would otherwise
// have to give it:
//   - a PM QoS CPU latency request (`machine.realtime.pm_qos_latency`, default 0 us on
//     /dev/cpu_dma_latency) held from before the first cycle until the tasks have stopped;
//   - locked memory (mlockall current and future pages, `machine.realtime.lock_memory`);
//   - per task thread, set by the thread on itself: SCHED_FIFO 90 − priority (never the whole
//     process: the main, bridge and logging threads stay SCHED_OTHER), the task's `cpu:`
//     affinity, and a pre-faulted stack;
//   - the process's other (non-RT) threads moved off the CPUs the tasks are pinned to, while
//     another CPU is left for them (keep_off_rt_cpus()), so that a task's wake-up never has to
//     preempt the bridge, the logger or the controlling thread; threads they start later inherit
//     it. Restored when the RtEnvironment ends.
// Nothing here is fatal: at start the runtime logs one line for each of these six items, at
// info when it was set up and at warn (with the reason and the remedy) when it was not.
//
// Non-RT: allocates and logs. RtEnvironment and PmQosRequest are thread-compatible (one
// controlling thread); setup_task_thread() is called by each task thread on itself, before its
// first cycle.

#include <sched.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "edm/runtime/config.hpp"

namespace edm::rt {

/// An open PM QoS request: the kernel keeps the latency requested while the file descriptor is
/// open and drops the request when it is closed, also when the process dies (kill -9 included).
class PmQosRequest {
 public:
  PmQosRequest() = default;
  ~PmQosRequest() { release(); }
  PmQosRequest(const PmQosRequest&) = delete;
  PmQosRequest& operator=(const PmQosRequest&) = delete;
  PmQosRequest(PmQosRequest&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  PmQosRequest& operator=(PmQosRequest&& other) noexcept;

  /// Opens `device` (non-blocking, so a FIFO without a reader fails instead of hanging) and
  /// writes latency_us as a binary s32, as /dev/cpu_dma_latency takes it. Releases any earlier
  /// request first. Returns "" on success, else why not ("open: Permission denied").
  std::string hold(const std::string& device, std::int32_t latency_us);
  /// Closes the request. Idempotent.
  void release() noexcept;
  [[nodiscard]] bool held() const noexcept { return fd_ >= 0; }

 private:
  int fd_{-1};
};

/// What one task thread could set up for itself (setup_task_thread()).
struct ThreadSetup {
  std::string task;
  int fifo_priority{0};             // the SCHED_FIFO priority asked for
  int fifo_error{0};                // 0: SCHED_FIFO set; else pthread_setschedparam's error
  std::optional<int> cpu;           // the task's `cpu:`, if any
  int affinity_error{0};            // 0: pinned (or nothing to pin); else the error
  std::size_t prefaulted_bytes{0};  // stack touched before the first cycle
  int tid{0};                       // the thread's kernel id (gettid)
};

/// Bytes of stack each task thread touches before its first cycle.
inline constexpr std::size_t kPrefaultStackBytes = 256 * 1024;

/// Called by a task thread on itself: SCHED_FIFO at fifo_priority(spec.priority), pinned to
/// spec.cpu when set, stack pre-faulted. Never throws and never logs (the controlling thread
/// reports the result through RtEnvironment::report_threads()).
ThreadSetup setup_task_thread(const TaskSpec& spec) noexcept;

class RtEnvironment {
 public:
  struct Line {
    bool ok;           // set up as asked (or deliberately switched off in the config)
    std::string text;  // what was logged
  };

  /// Holds the PM QoS request and locks memory as `spec` says, and logs one line for each.
  explicit RtEnvironment(const RealtimeSpec& spec);
  /// Releases the PM QoS request and unlocks the memory it locked.
  ~RtEnvironment();
  RtEnvironment(const RtEnvironment&) = delete;
  RtEnvironment& operator=(const RtEnvironment&) = delete;

  /// Logs one line each for the task threads' SCHED_FIFO, CPU affinity and stacks.
  void report_threads(const std::vector<ThreadSetup>& threads);
  /// Moves every thread of the process but the task threads to the allowed CPUs that no task is
  /// pinned to (when there is at least one), and logs one line saying what it did.
  void keep_off_rt_cpus(const std::vector<ThreadSetup>& threads);

  [[nodiscard]] bool pm_qos_held() const noexcept { return pm_qos_.held(); }
  [[nodiscard]] bool memory_locked() const noexcept { return memory_locked_; }
  /// Every line logged so far, in order.
  [[nodiscard]] const std::vector<Line>& lines() const noexcept { return lines_; }

 private:
  void add(bool ok, std::string text);

  PmQosRequest pm_qos_;
  bool memory_locked_{false};
  struct Moved {
    int tid;
    cpu_set_t before;
  };
  std::vector<Moved> moved_;  // threads keep_off_rt_cpus() moved, restored at the end
  std::vector<Line> lines_;
};

}  // namespace edm::rt
