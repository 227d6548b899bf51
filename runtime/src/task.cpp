#include "edm/runtime/task.hpp"

#include "edm/runtime/supervisor.hpp"
#include "edm/runtime/trace.hpp"
#include "edm/runtime/variables.hpp"

namespace edm::rt {

Task::Task(TaskSpec spec, Machine& machine)
    : spec_(std::move(spec)),
      machine_(&machine),
      watchdog_(spec_.watchdog),
      dt_s_(to_seconds(spec_.interval)) {}

bool Task::post_param_write(const ParamWrite& w) {
  std::lock_guard lock(producer_mutex_);
  return param_writes_.push(w);
}

void Task::apply_pending_param_writes() noexcept {
  ParamWrite w;
  while (param_writes_.pop(w)) {
    w.block->apply_param(w.index, w.value);
  }
}

void Task::on_safe_state(MachineState s) noexcept {
  const SafeStateRequest r{s, machine_->last_cause()};
  // The driver first: the generator goes off before any program reacts.
  if (driver_ != nullptr) {
    driver_->enter_safe_state(r);
  }
  for (Program* p : programs_) {
    p->enter_safe_state(r);
  }
}

void Task::enter_safe_state_now(const SafeStateRequest& r) noexcept {
  if (driver_ != nullptr) {
    driver_->enter_safe_state(r);
  }
  for (Program* p : programs_) {
    p->enter_safe_state(r);
  }
}

TimePoint Task::run_cycle(TimePoint release, const Clock& clock) noexcept {
  const TimePoint start = clock.now();
  // The thread's CPU time, to tell a host stall from an overrun (judge_cycle); only for a task
  // with a watchdog (one system call on the real clock).
  const Duration cpu_start = watchdog_.enabled() ? clock.thread_cpu_time() : Duration{};
  apply_pending_param_writes();

  machine_->note_release(release);
  const std::uint64_t epoch = machine_->safe_epoch();
  const MachineState state = machine_->state();
  if (epoch != seen_safe_epoch_) {
    seen_safe_epoch_ = epoch;
    if (is_safe_state(state)) {
      on_safe_state(state);
    }
  }
  // Before the programs run and the outputs are latched: a forced velocity or generator pin
  // never reaches the machine in a safe state, and reset finds nothing forced to bring back.
  if (forces_ != nullptr && is_safe_state(state)) {
    if (const std::size_t n = forces_->release_forces(); n > 0) {
      Alarm a;
      a.code = AlarmCode::kForcesReleased;
      a.severity = AlarmSeverity::kWarning;
      a.time = release;
      a.source = spec_.name.c_str();
      a.text = "safe state: every forced pin was released";
      a.value = static_cast<double>(n);
      machine_->raise(a);
    }
  }

  const std::uint64_t cycle = cycle_.load(std::memory_order_relaxed);
  const CycleContext ctx{release, spec_.interval, dt_s_, cycle, state, &clock};

  if (driver_ != nullptr) {
    driver_->read_inputs(ctx);
    const IoFault f = driver_->fault();
    if (f.code != 0 && !driver_faulted_) {
      Alarm a;
      a.code = AlarmCode::kIoFault;
      a.time = release;
      a.source = "io";
      a.text = f.text;
      a.value = f.code;
      machine_->raise(a);
    } else if (f.code == 0 && driver_faulted_) {
      machine_->clear_alarm(AlarmCode::kIoFault, "io");
    }
    driver_faulted_ = f.code != 0;
  }
  for (Program* p : programs_) {
    p->run(ctx);
  }
  if (supervisor_ != nullptr) {
    supervisor_->supervise(ctx, start);  // the driver read the inputs just after `start`
  }
  if (driver_ != nullptr) {
    driver_->write_outputs(ctx);
  }
  if (trace_ != nullptr) {
    trace_->sample(trace_channel_, release, cycle);
  }
  for (CycleObserver* o : observers_) {
    o->on_cycle_end(ctx);
  }

  const TimePoint end = clock.now();
  const Duration exec = end - start;
  stats_.record_cycle(start - release, exec);
  judge_cycle(release, exec, clock, cpu_start);
  cycle_.store(cycle + 1, std::memory_order_relaxed);
  return end;
}

void Task::judge_cycle(TimePoint release, Duration exec, const Clock& clock,
                       Duration cpu_start) noexcept {
  if (!watchdog_.enabled()) {
    return;
  }
  // A cycle over `time` whose own CPU time stayed within it was late because the thread did not
  // run (the process descheduled, the hypervisor's vCPU stolen), not because of its work.
  bool stalled = false;
  if (exec > spec_.watchdog.time) {
    const Duration cpu = clock.thread_cpu_time() - cpu_start;
    stalled = cpu <= spec_.watchdog.time;
  }
  if (stalled) {
    host_stalls_.fetch_add(1, std::memory_order_relaxed);
    const auto stall_ns = exec.count();
    if (stall_ns > longest_stall_ns_.load(std::memory_order_relaxed)) {
      longest_stall_ns_.store(stall_ns, std::memory_order_relaxed);
    }
    stall_latched_ = true;
    Alarm a;
    a.code = AlarmCode::kHostStall;
    a.severity = AlarmSeverity::kWarning;
    a.time = release;
    a.source = spec_.name.c_str();
    a.value = to_micros(exec);
    a.text = spec_.watchdog.host_stall == HostStallPolicy::kTolerate
                 ? "host stall: the task was descheduled in its cycle (tolerated: host_stall)"
                 : "host stall: the task was descheduled in its cycle (judged by the watchdog)";
    machine_->raise(a);
    if (spec_.watchdog.host_stall == HostStallPolicy::kTolerate) {
      return;  // neither counted against the watchdog nor ending an overload
    }
  } else if (stall_latched_ && exec <= spec_.watchdog.time) {
    stall_latched_ = false;
    machine_->clear_alarm(AlarmCode::kHostStall, spec_.name.c_str());
  }

  if (watchdog_.check(exec) != WatchdogVerdict::kTrip) {
    // Only a cycle in time ends the occurrence; an overload that goes on is one alarm, counted.
    if (watchdog_tripped_ && watchdog_.consecutive() == 0) {
      watchdog_tripped_ = false;
      machine_->clear_alarm(AlarmCode::kWatchdog, spec_.name.c_str());
      machine_->clear_alarm(AlarmCode::kWatchdogWarning, spec_.name.c_str());
    }
    return;
  }
  watchdog_tripped_ = true;
  Alarm a;
  a.time = release;
  a.source = spec_.name.c_str();
  a.value = to_micros(exec);
  if (spec_.watchdog.action == WatchdogAction::kFault) {
    a.code = AlarmCode::kWatchdog;
    a.severity = AlarmSeverity::kFault;
    a.text = "watchdog: cycle execution time exceeded";
  } else {
    a.code = AlarmCode::kWatchdogWarning;
    a.severity = AlarmSeverity::kWarning;
    a.text = "watchdog warning: cycle execution time exceeded";
    watchdog_warnings_.fetch_add(1, std::memory_order_relaxed);
  }
  machine_->raise(a);
}

}  // namespace edm::rt
