#include "edm/runtime/machine.hpp"

namespace edm::rt {

std::string_view to_string(MachineState s) noexcept {
  switch (s) {
    case MachineState::kOff:
      return "OFF";
    case MachineState::kReady:
      return "READY";
    case MachineState::kRunning:
      return "RUNNING";
    case MachineState::kHold:
      return "HOLD";
    case MachineState::kFault:
      return "FAULT";
    case MachineState::kEstop:
      return "ESTOP";
  }
  return "?";
}

std::string_view to_string(MachineCommand c) noexcept {
  switch (c) {
    case MachineCommand::kPowerOn:
      return "power_on";
    case MachineCommand::kStart:
      return "start";
    case MachineCommand::kHold:
      return "hold";
    case MachineCommand::kResume:
      return "resume";
    case MachineCommand::kStop:
      return "stop";
    case MachineCommand::kReset:
      return "reset";
    case MachineCommand::kEstop:
      return "estop";
    case MachineCommand::kPowerOff:
      return "power_off";
  }
  return "?";
}

std::string_view to_string(AlarmCode c) noexcept {
  switch (c) {
    case AlarmCode::kNone:
      return "none";
    case AlarmCode::kWatchdog:
      return "watchdog";
    case AlarmCode::kWatchdogWarning:
      return "watchdog_warning";
    case AlarmCode::kBlockFault:
      return "block_fault";
    case AlarmCode::kIoFault:
      return "io_fault";
    case AlarmCode::kEstop:
      return "estop";
    case AlarmCode::kFollowingError:
      return "following_error";
    case AlarmCode::kSoftLimit:
      return "soft_limit";
    case AlarmCode::kShortCircuit:
      return "short_circuit";
    case AlarmCode::kElectrodeUsedUp:
      return "electrode_used_up";
    case AlarmCode::kWireBreak:
      return "wire_break";
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
      if (c == MachineCommand::kEstop) {
        Alarm a;
        a.code = AlarmCode::kEstop;
        a.time = now;
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

void Machine::raise(const Alarm& a) noexcept {
  if (!alarms_.push(a)) {
    dropped_alarms_.fetch_add(1, std::memory_order_relaxed);
  }
  if (a.severity != AlarmSeverity::kFault) {
    return;
  }
  for (;;) {
    const MachineState s = state();
    // ESTOP outranks FAULT; OFF has nothing energised; an existing FAULT keeps its first cause.
    if (s == MachineState::kEstop || s == MachineState::kOff || s == MachineState::kFault) {
      return;
    }
    if (transition(s, MachineState::kFault, a.code)) {
      return;
    }
  }
}

}  // namespace edm::rt
