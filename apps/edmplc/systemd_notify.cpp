#include "systemd_notify.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>
#include <vector>

#include "edm/runtime/machine.hpp"
#include "edm/runtime/task.hpp"
#include "edm/runtime/time.hpp"

#ifdef EDM_HAVE_LIBSYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace edmplc {

namespace {

void send(const std::string& state) {
#ifdef EDM_HAVE_LIBSYSTEMD
  if (const int r = sd_notify(0, state.c_str()); r < 0) {
    spdlog::warn("systemd: sd_notify({}) failed: error {}", state.substr(0, state.find('\n')), -r);
  }
#else
  (void)state;
#endif
}

std::string status_line(edm::rt::Runtime& rt) {
  return "STATUS=machine " + std::string(to_string(rt.machine().state())) + ", " +
         std::to_string(rt.tasks().size()) + " task(s) cycling";
}

}  // namespace

SystemdNotifier::SystemdNotifier(edm::rt::Runtime& rt,
                                 const std::atomic<bool>& stop_requested) noexcept
    : rt_(rt), stop_requested_(stop_requested) {}

SystemdNotifier::~SystemdNotifier() { stop(); }

void SystemdNotifier::start() {
  if (std::getenv("NOTIFY_SOCKET") == nullptr) {
    return;  // not started by systemd (or not as Type=notify): nothing to tell
  }
#ifdef EDM_HAVE_LIBSYSTEMD
  std::uint64_t watchdog_us = 0;
  if (sd_watchdog_enabled(0, &watchdog_us) <= 0) {
    watchdog_us = 0;
  }
  thread_ = std::thread([this, watchdog_us] { loop(watchdog_us); });
#else
  spdlog::warn(
      "systemd: $NOTIFY_SOCKET is set but this edmplc was built without libsystemd: no READY=1 "
      "or WATCHDOG=1 (build with libsystemd-dev, or run the unit as Type=simple without "
      "WatchdogSec)");
#endif
}

void SystemdNotifier::stop() {
  {
    const std::lock_guard lock(mutex_);
    quit_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) {
    notify_stopping();
    thread_.join();
  }
}

void SystemdNotifier::notify_stopping() {
  if (!stopping_sent_.exchange(true)) {
    send("STOPPING=1\nSTATUS=stopping: safe state, tasks joined, retain flushed");
  }
}

bool SystemdNotifier::wait_ms(std::int64_t ms) {
  std::unique_lock lock(mutex_);
  return !cv_.wait_for(lock, std::chrono::milliseconds(ms), [this] { return quit_; });
}

void SystemdNotifier::loop(std::uint64_t watchdog_us) {
  const auto& tasks = rt_.tasks();
  // READY=1: powered on and every task has run a cycle (the bridge is already listening).
  for (;;) {
    if (!wait_ms(10)) {
      return;
    }
    if (stop_requested_.load()) {
      notify_stopping();
      return;
    }
    const bool all_cycled =
        std::all_of(tasks.begin(), tasks.end(), [](const auto& t) { return t->cycles() > 0; });
    if (all_cycled && rt_.machine().state() != edm::rt::MachineState::kOff) {
      break;
    }
  }
  send("READY=1\n" + status_line(rt_));

  // Every task must cycle at least once between two checks: the check period is a quarter of
  // WatchdogSec, but never shorter than two intervals of the slowest task.
  edm::rt::Duration slowest{};
  for (const auto& t : tasks) {
    slowest = std::max(slowest, t->spec().interval);
  }
  const std::int64_t slowest_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(slowest).count();
  const std::int64_t watchdog_ms = static_cast<std::int64_t>(watchdog_us / 1000);
  std::int64_t period_ms = watchdog_ms > 0 ? watchdog_ms / 4 : 1000;
  period_ms = std::max({period_ms, 2 * slowest_ms + 1, std::int64_t{10}});
  if (watchdog_ms > 0) {
    spdlog::info(
        "systemd: watchdog {} ms, fed every {} ms while every task cycles (the tasks' own "
        "watchdogs trip on late cycles; this one on a task that stops cycling)",
        watchdog_ms, period_ms);
    if (2 * period_ms > watchdog_ms) {
      spdlog::warn(
          "systemd: WatchdogSec={} ms is short for the slowest task's interval ({}): set it to "
          "at least {} ms",
          watchdog_ms, edm::rt::format_duration(slowest), 8 * slowest_ms);
    }
  }

  std::vector<std::uint64_t> last(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    last[i] = tasks[i]->cycles();
  }
  auto state = rt_.machine().state();
  bool stalled = false;
  while (wait_ms(period_ms)) {
    if (stop_requested_.load()) {
      notify_stopping();
      return;
    }
    const edm::rt::Task* stuck = nullptr;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const std::uint64_t now = tasks[i]->cycles();
      if (now == last[i] && stuck == nullptr) {
        stuck = tasks[i].get();
      }
      last[i] = now;
    }
    if (stuck != nullptr) {
      if (!stalled) {
        spdlog::error("systemd: task '{}' ran no cycle in {} ms: the watchdog is not fed",
                      stuck->name(), period_ms);
      }
      stalled = true;
      continue;
    }
    if (stalled) {
      spdlog::warn("systemd: every task cycles again: the watchdog is fed again");
      stalled = false;
    }
    std::string message;
    if (watchdog_ms > 0) {
      message = "WATCHDOG=1";
    }
    if (const auto s = rt_.machine().state(); s != state) {
      state = s;
      message += (message.empty() ? "" : "\n") + status_line(rt_);
    }
    if (!message.empty()) {
      send(message);
    }
  }
}

}  // namespace edmplc
