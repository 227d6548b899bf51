#pragma once
// edmplc under systemd (packaging/systemd/edmplc.service, Type=notify, docs/deploy.md): READY=1
// once the machine is powered on and every task has cycled, WATCHDOG=1 while every task keeps
// cycling, STOPPING=1 when a stop is requested. Nothing happens without $NOTIFY_SOCKET.
//
// The systemd watchdog is the backstop of the tasks' own watchdogs: those trip (FAULT, safe
// state) on cycles that end too late, but they run in the task threads and cannot see a task
// that stops cycling at all (a hung thread or process); this one can. The process stays alive
// and fed in FAULT: the safe state is held by running tasks, and a restart would not clear it.
//
// Thread safety: start() and stop() from the controlling thread only. The notifier runs its own
// ordinary (SCHED_OTHER, unpinned) thread that reads only lock-free counters of the runtime
// (Task::cycles(), Machine::state()); the RT cycle knows nothing of it.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "edm/runtime/runtime.hpp"

namespace edmplc {

class SystemdNotifier {
 public:
  /// `rt` and `stop_requested` (set by the signal handler) must outlive the notifier.
  SystemdNotifier(edm::rt::Runtime& rt, const std::atomic<bool>& stop_requested) noexcept;
  ~SystemdNotifier();
  SystemdNotifier(const SystemdNotifier&) = delete;
  SystemdNotifier& operator=(const SystemdNotifier&) = delete;

  /// Starts the notifier thread when $NOTIFY_SOCKET is set (before Runtime::run()). Non-RT.
  void start();
  /// Sends STOPPING=1 (once) and joins the thread. Non-RT; idempotent.
  void stop();

 private:
  void loop(std::uint64_t watchdog_us);
  /// Waits up to `ms`; false when stop() was called meanwhile.
  bool wait_ms(std::int64_t ms);
  void notify_stopping();

  edm::rt::Runtime& rt_;
  const std::atomic<bool>& stop_requested_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool quit_{false};  // guarded by mutex_
  std::atomic<bool> stopping_sent_{false};
};

}  // namespace edmplc
