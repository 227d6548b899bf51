#pragma once
// A Runtime's run() on a thread of its own until stop(), for tests that work a running machine
// from outside it (a server beside it, a writer): start, wait for the power-on, stop and join.

#include <atomic>
#include <chrono>
#include <thread>

#include "edm/runtime/machine.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::test {

/// The virtual clock paced to `speed` × wall time: deterministic, yet followable from outside.
inline rt::RunOptions paced_virtual_clock(double speed) {
  rt::RunOptions o;
  o.clock = rt::ClockKind::kVirtual;
  o.speed = speed;
  return o;
}

class RuntimeThread {
 public:
  RuntimeThread() = default;
  RuntimeThread(const RuntimeThread&) = delete;
  RuntimeThread& operator=(const RuntimeThread&) = delete;
  ~RuntimeThread() { stop(); }

  /// Runs rt.run(options) on the thread, with this object's stop flag. rt must outlive the
  /// thread: stop() before it goes.
  void start(rt::Runtime& rt, rt::RunOptions options = {}) {
    rt_ = &rt;
    options.stop = &stop_;
    thread_ = std::thread([&rt, options] { rt.run(options); });
  }
  /// Waits up to 10 s for run() to power the machine on (OFF → READY, on its thread): for that
  /// state, not for a time. True once it has.
  bool wait_until_powered_on() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (rt_->machine().state() == rt::MachineState::kOff &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::yield();
    }
    return rt_->machine().state() != rt::MachineState::kOff;
  }
  /// Asks run() to return and joins the thread; nothing when it was not started.
  void stop() {
    stop_ = true;
    if (thread_.joinable()) {
      thread_.join();
    }
  }

 private:
  rt::Runtime* rt_{nullptr};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace edm::test
