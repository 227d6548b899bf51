#include "edm/runtime/runtime.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "edm/runtime/alarm_help.hpp"
#include "edm/runtime/rt_environment.hpp"
#include "edm/runtime/scheduler.hpp"

namespace edm::rt {

std::optional<std::string> Runtime::set_condition_field(int e, std::string_view field,
                                                        double value) {
  const std::vector<std::string>& allowed = config_.machine.condition_edit;
  if (std::find(allowed.begin(), allowed.end(), field) == allowed.end()) {
    return "'" + std::string(field) + "' of a condition may not be changed on this machine" +
           (allowed.empty() ? std::string(" (machine.condition_edit lists none)")
                            : " (machine.condition_edit)");
  }
  machining::Condition* c = nullptr;
  for (machining::Condition& x : tables_.conditions) {
    if (x.e == e) c = &x;
  }
  if (c == nullptr) return "this machine has no condition E" + std::to_string(e);
  if (auto why = machining::condition_value_error(field, value)) return why;
  *machining::condition_field(*c, field) = value;
  return std::nullopt;
}

Runtime::~Runtime() {
  // A runtime that never ran (a failed start) has nothing new to keep: it must not write.
  if (retain_ && ran_) {
    retain_->stop();
  }
}

Program* Runtime::program(std::string_view name) const {
  for (const auto& p : programs_) {
    if (p->name() == name) {
      return p.get();
    }
  }
  return nullptr;
}

std::vector<TaskStatsReport> Runtime::stats_reports() const {
  std::vector<TaskStatsReport> out;
  for (const auto& t : tasks_) {
    out.push_back({t->name(), t->spec().interval, t->spec().priority, t->stats().snapshot()});
  }
  return out;
}

void Runtime::drain_alarms() {
  Alarm a;
  while (machine_.pop_alarm(a)) {
    const double t_s = to_seconds(a.time);  // the release time of the cycle that raised it
    const std::string_view remedy = alarm_help(a.code).remedy;
    if (a.severity == AlarmSeverity::kFault) {
      spdlog::error("ALARM {} ({}) from {} at t={:.6f}s: {} [value {}]; remedy: {}",
                    static_cast<int>(a.code), to_string(a.code), a.source, t_s, a.text, a.value,
                    remedy);
    } else {
      spdlog::warn("alarm {} ({}) from {} at t={:.6f}s: {} [value {}]; remedy: {}",
                   static_cast<int>(a.code), to_string(a.code), a.source, t_s, a.text, a.value,
                   remedy);
    }
    for (const auto& listener : alarm_listeners_) {
      listener(a);
    }
  }
}

RunSummary Runtime::run(const RunOptions& options) {
  std::vector<Task*> tasks;
  for (auto& t : tasks_) {
    tasks.push_back(t.get());
  }
  ran_ = true;
  if (machine_.state() == MachineState::kOff) {
    machine_.command(MachineCommand::kPowerOn);
  }
  if (startup_alarm_ != AlarmCode::kNone) {
    // Comes up in FAULT: the operator acknowledges (reset) that retained values were lost.
    Alarm a;
    a.code = startup_alarm_;
    a.severity = AlarmSeverity::kFault;
    a.source = "retain";
    a.text = retain_warning_.c_str();
    // Before the first cycle: the start time on the clock the tasks will use (virtual: 0).
    a.time = options.clock == ClockKind::kReal ? RealClock{}.now() : TimePoint{};
    machine_.raise(a);
    startup_alarm_ = AlarmCode::kNone;
  }
  if (interrupted_job_ && !job_alarm_raised_) {
    // Comes up in FAULT: the operator checks the work before anything moves (DESIGN §11).
    Alarm a;
    a.code = AlarmCode::kJobInterrupted;
    a.severity = AlarmSeverity::kFault;
    a.source = "job";
    a.text = job_alarm_text_.c_str();
    a.value = interrupted_job_->depth_mm.value_or(std::nan(""));
    a.time = options.clock == ClockKind::kReal ? RealClock{}.now() : TimePoint{};
    machine_.raise(a);
    job_alarm_raised_ = true;
  }
  for (const auto& t : tasks_) {
    const WatchdogSpec& w = t->spec().watchdog;
    if (w.enabled && w.host_stall == HostStallPolicy::kTolerate) {
      spdlog::info(
          "task '{}': host stalls tolerated (watchdog host_stall: tolerate): a cycle late only "
          "because the host descheduled the process is warning 102, not a watchdog fault; a "
          "setting for simulated machines",
          t->name());
    }
  }
  if (options.trace_out.empty()) {
    // Nobody drains the rings without a trace file: don't sample, don't count drops.
    for (auto& t : tasks_) {
      t->detach_trace();
    }
    has_trace_ = false;
  }
  RunSummary summary;
  // A field-bus driver's own thread runs while the tasks do (io_driver.hpp); stopped last, after
  // the tasks' final safe state, so that it can still send the safe outputs.
  struct DriverRun {
    IoDriver* driver;
    ~DriverRun() {
      if (driver != nullptr) {
        driver->stop();
      }
    }
  } const driver_run{driver_.get()};
  if (driver_) {
    driver_->start();
  }
  const auto stop_requested = [&] {
    return options.stop != nullptr && options.stop->load(std::memory_order_relaxed);
  };

  if (options.clock == ClockKind::kVirtual) {
    VirtualClock clock;
    std::ofstream trace_file;
    if (!options.trace_out.empty() && has_trace_) {
      trace_file.open(options.trace_out, std::ios::out | std::ios::trunc);
      if (!trace_file) {
        throw std::runtime_error(options.trace_out + ": " + std::strerror(errno));
      }
    }
    VirtualScheduler sched(tasks, clock);
    // Virtual time has no deadline: drain the trace between cycles so nothing is dropped and
    // the CSV is identical from run to run.
    std::uint64_t n = 0;
    const TimePoint wall_start = RealClock{}.now();
    auto between = [&] {
      if (trace_file.is_open() && has_trace_) {
        trace_.drain(trace_file);
      }
      if (options.speed > 0.0 && (n & 63) == 0) {  // paced: virtual t = speed × wall t
        const auto wall = std::chrono::duration<double>(clock.now()) / options.speed;
        RealClock::sleep_until(wall_start + std::chrono::duration_cast<Duration>(wall));
      }
      if ((++n & 1023) == 0) {
        drain_alarms();
        if (retain_) {
          retain_->poll(clock.now());
        }
      }
    };
    const TimePoint end = options.run_for ? TimePoint{*options.run_for}
                                          : TimePoint{std::numeric_limits<std::int64_t>::max()};
    sched.run_until(end, between, options.stop);
    for (auto& t : tasks_) {
      t->enter_safe_state_now({MachineState::kOff, AlarmCode::kNone});
    }
    if (trace_file.is_open() && has_trace_) {
      trace_.drain(trace_file);
    }
  } else {
    // Held until the tasks have stopped (end of this block): PM QoS request, locked memory.
    RtEnvironment rt_env(config_.machine.realtime);
    RealClock clock;
    if (!options.trace_out.empty() && has_trace_) {
      trace_.start_file_writer(options.trace_out);
    }
    if (retain_) {
      retain_->start(std::chrono::milliseconds(100));
    }
    RealTimeScheduler sched;
    sched.start(tasks, clock, options.run_for);
    rt_env.report_threads(sched.thread_setups());
    rt_env.keep_off_rt_cpus(sched.thread_setups());
    // With run_for the tasks stop by themselves at T0 + run_for (exact cycle counts); the
    // controlling thread only watches the time and the stop flag.
    const TimePoint deadline = sched.end();
    while (!stop_requested() && clock.now() < deadline) {
      drain_alarms();
      const TimePoint wake = std::min(deadline, clock.now() + std::chrono::milliseconds(20));
      RealClock::sleep_until(wake);
    }
    sched.stop();
    summary.fifo_degraded = sched.degraded();
    for (auto& t : tasks_) {
      t->enter_safe_state_now({MachineState::kOff, AlarmCode::kNone});
    }
    if (has_trace_ && !options.trace_out.empty()) {
      trace_.stop();
    }
  }
  if (retain_) {
    retain_->stop();
  }
  drain_alarms();
  for (const auto& t : tasks_) {
    if (const std::uint64_t n = t->host_stalls(); n > 0) {
      spdlog::warn("task '{}': {} host stall(s), the longest cycle {:.3f} ms ({})", t->name(), n,
                   to_micros(t->longest_host_stall()) / 1000.0,
                   t->spec().watchdog.host_stall == HostStallPolicy::kTolerate
                       ? "tolerated"
                       : "judged by the watchdog");
    }
  }
  summary.final_state = machine_.state();
  summary.trace_dropped = has_trace_ ? trace_.dropped() : 0;
  summary.alarms_dropped = machine_.dropped_alarms();
  return summary;
}

}  // namespace edm::rt
