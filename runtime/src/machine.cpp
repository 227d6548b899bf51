#include "edm/runtime/machine.hpp"

#include <cstring>

namespace edm::rt {

std::string_view to_string(MachineState s) noexcept {
  switch (s) {
    case MachineState::kOff: return "OFF";
    case MachineState::kReady: return "READY";
    case MachineState::kRunning: return "RUNNING";
    case MachineState::kHold: return "HOLD";
    case MachineState::kFault: return "FAULT";
    case MachineState::kEstop: return "ESTOP";
  }
  return "?";
}

std::string_view to_string(MachineCommand c) noexcept {
  switch (c) {
    case MachineCommand::kPowerOn: return "power_on";
    case MachineCommand::kStart: return "start";
    case MachineCommand::kHold: return "hold";
    case MachineCommand::kResume: return "resume";
    case MachineCommand::kStop: return "stop";
    case MachineCommand::kReset: return "reset";
    case MachineCommand::kEstop: return "estop";
    case MachineCommand::kPowerOff: return "power_off";
  }
  return "?";
}

std::string_view to_string(AlarmCode c) noexcept {
  switch (c) {
    case AlarmCode::kNone: return "none";
    case AlarmCode::kWatchdog: return "watchdog";
    case AlarmCode::kWatchdogWarning: return "watchdog_warning";
    case AlarmCode::kHostStall: return "host_stall";
    case AlarmCode::kBlockFault: return "block_fault";
    case AlarmCode::kIoFault: return "io_fault";
    case AlarmCode::kIoStale: return "io_stale";
    case AlarmCode::kEstop: return "estop";
    case AlarmCode::kInterlockOpen: return "interlock_open";
    case AlarmCode::kFollowingError: return "following_error";
    case AlarmCode::kSoftLimit: return "soft_limit";
    case AlarmCode::kShortCircuit: return "short_circuit";
    case AlarmCode::kElectrodeUsedUp: return "electrode_used_up";
    case AlarmCode::kWireBreak: return "wire_break";
    case AlarmCode::kRetainCorrupt: return "retain_corrupt";
    case AlarmCode::kForcesReleased: return "forces_released";
    case AlarmCode::kJobInterrupted: return "job_interrupted";
    case AlarmCode::kRetainWriteFailed: return "retain_write_failed";
  }
  return "?";
}

bool Machine::transition(MachineState from, MachineState to, AlarmCode cause) noexcept {
  if (!state_.compare_exchange_strong(from, to, std::memory_order_acq_rel)) {
    return false;
  }
  if (is_safe_state(to)) {
    last_cause_.store(cause, std::memory_order_release);
    safe_epoch_.fetch_add(1, std::memory_order_acq_rel);
  }
  return true;
}

bool Machine::set_feed_override(double ratio) noexcept {
  if (!(ratio >= 0.0 && ratio <= kMaxFeedOverride)) return false;  // NaN fails both
  feed_override_.store(ratio, std::memory_order_relaxed);
  return true;
}

CommandResult Machine::command(MachineCommand c, TimePoint now) noexcept {
  // Retry on races with other threads (an RT fault landing between load and CAS).
  for (;;) {
    const MachineState s = state();
    MachineState to = s;
    AlarmCode cause = AlarmCode::kNone;
    switch (c) {
      case MachineCommand::kPowerOn:
        if (s != MachineState::kOff) return CommandResult::kInvalidState;
        to = MachineState::kReady;
        break;
      case MachineCommand::kStart:
        if (s != MachineState::kReady) return CommandResult::kInvalidState;
        to = MachineState::kRunning;
        break;
      case MachineCommand::kHold:
        if (s != MachineState::kRunning) return CommandResult::kInvalidState;
        to = MachineState::kHold;
        break;
      case MachineCommand::kResume:
        if (s != MachineState::kHold) return CommandResult::kInvalidState;
        to = MachineState::kRunning;
        break;
      case MachineCommand::kStop:
        if (s != MachineState::kRunning && s != MachineState::kHold) {
          return CommandResult::kInvalidState;
        }
        to = MachineState::kReady;
        break;
      case MachineCommand::kReset:
        if (!is_safe_state(s)) return CommandResult::kInvalidState;
        to = MachineState::kReady;
        break;
      case MachineCommand::kEstop:
        if (s == MachineState::kEstop) return CommandResult::kOk;  // idempotent
        to = MachineState::kEstop;
        cause = AlarmCode::kEstop;
        break;
      case MachineCommand::kPowerOff:
        if (s != MachineState::kReady && s != MachineState::kOff && !is_safe_state(s)) {
          return CommandResult::kInvalidState;
        }
        to = MachineState::kOff;
        break;
    }
    if (transition(s, to, cause)) {
      if (c == MachineCommand::kReset) {
        clear_all_latches();  // after reset, a condition that persists is a new occurrence
      }
      if (c == MachineCommand::kEstop) {
        Alarm a;
        a.code = AlarmCode::kEstop;
        a.time = now != TimePoint{} ? now : last_release();
        a.source = "operator";
        a.text = "emergency stop";
        if (!alarms_.push(a)) {
          dropped_alarms_.fetch_add(1, std::memory_order_relaxed);
        }
      }
      return CommandResult::kOk;
    }
  }
}

namespace {

bool same_source(const char* a, const char* b) noexcept {
  return a == b || (a != nullptr && b != nullptr && std::strcmp(a, b) == 0);
}

}  // namespace

void Machine::enter_fault(AlarmCode cause) noexcept {
  for (;;) {
    const MachineState s = state();
    // ESTOP outranks FAULT; OFF has nothing energised; an existing FAULT keeps its first cause.
    if (s == MachineState::kEstop || s == MachineState::kOff || s == MachineState::kFault) {
      return;
    }
    if (transition(s, MachineState::kFault, cause)) {
      return;
    }
  }
}

bool Machine::raise(const Alarm& in) noexcept {
  Alarm a = in;
  if (a.time == TimePoint{}) {
    a.time = last_release();
  }
  bool fresh = true;
  for (Latch& l : latches_) {
    if (l.state.load(std::memory_order_acquire) == 2 &&
        l.code.load(std::memory_order_relaxed) == a.code &&
        same_source(l.source.load(std::memory_order_relaxed), a.source)) {
      l.count.fetch_add(1, std::memory_order_relaxed);
      repeated_alarms_.fetch_add(1, std::memory_order_relaxed);
      fresh = false;
      break;
    }
  }
  if (fresh) {
    for (Latch& l : latches_) {
      std::uint32_t expected = 0;
      if (l.state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
        l.code.store(a.code, std::memory_order_relaxed);
        l.source.store(a.source, std::memory_order_relaxed);
        l.first_ns.store(a.time.count(), std::memory_order_relaxed);
        l.count.store(1, std::memory_order_relaxed);
        l.text.store(a.text != nullptr ? a.text : "", std::memory_order_relaxed);
        l.value.store(a.value, std::memory_order_relaxed);
        l.state.store(2, std::memory_order_release);
        break;
      }
    }
    if (!alarms_.push(a)) {
      dropped_alarms_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  // A repeat still enforces FAULT: a latched fault must never leave the machine running.
  if (a.severity == AlarmSeverity::kFault) {
    enter_fault(a.code);
  }
  return fresh;
}

void Machine::clear_alarm(AlarmCode code, const char* source) noexcept {
  for (Latch& l : latches_) {
    if (l.state.load(std::memory_order_acquire) == 2 &&
        l.code.load(std::memory_order_relaxed) == code &&
        same_source(l.source.load(std::memory_order_relaxed), source)) {
      std::uint32_t expected = 2;
      l.state.compare_exchange_strong(expected, 0, std::memory_order_acq_rel);
    }
  }
}

void Machine::clear_all_latches() noexcept {
  for (Latch& l : latches_) {
    std::uint32_t expected = 2;
    l.state.compare_exchange_strong(expected, 0, std::memory_order_acq_rel);
  }
}

std::size_t Machine::active_alarms(ActiveAlarm* out, std::size_t capacity) const noexcept {
  std::size_t n = 0;
  for (const Latch& l : latches_) {
    if (n == capacity) {
      break;
    }
    if (l.state.load(std::memory_order_acquire) != 2) {
      continue;
    }
    out[n++] = ActiveAlarm{l.code.load(std::memory_order_relaxed),
                           l.source.load(std::memory_order_relaxed),
                           TimePoint{l.first_ns.load(std::memory_order_relaxed)},
                           l.count.load(std::memory_order_relaxed),
                           l.text.load(std::memory_order_relaxed),
                           l.value.load(std::memory_order_relaxed)};
  }
  return n;
}

void Machine::note_release(TimePoint release) noexcept {
  // Latest writer wins: tasks differ by less than a cycle, and a new virtual run starts at 0.
  last_release_ns_.store(release.count(), std::memory_order_relaxed);
}

}  // namespace edm::rt
