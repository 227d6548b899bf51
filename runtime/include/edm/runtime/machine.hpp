#pragma once
// The machine state machine (OFF, READY, RUNNING, HOLD, FAULT, ESTOP) and the alarm queue.
//
// Transitions (docs/runtime.md has the diagram):
//   OFF     --power_on-->  READY          READY   --start-->  RUNNING
//   RUNNING --hold-->      HOLD           HOLD    --resume--> RUNNING
//   RUNNING|HOLD --stop--> READY          READY   --power_off--> OFF
//   any but OFF, ESTOP --fault--> FAULT   any --estop--> ESTOP
//   FAULT|ESTOP --reset--> READY
// Entering FAULT or ESTOP bumps safe_epoch(); every task sees the new epoch at the start of its
// next cycle and calls the safe-state hooks of its programs and (for the I/O task) the driver.
//
// Thread-safety: every member is lock-free and may be called from any thread, RT included.

#include <atomic>
#include <boost/lockfree/queue.hpp>
#include <cstdint>
#include <string_view>

#include "edm/runtime/time.hpp"

namespace edm::rt {

enum class MachineState : std::uint8_t { kOff, kReady, kRunning, kHold, kFault, kEstop };
enum class MachineCommand : std::uint8_t {
  kPowerOn,
  kStart,
  kHold,
  kResume,
  kStop,
  kReset,
  kEstop,
  kPowerOff
};

std::string_view to_string(MachineState s) noexcept;
std::string_view to_string(MachineCommand c) noexcept;

/// Is this a state in which the machine must be (and stay) safe: generator off, axes stopped?
constexpr bool is_safe_state(MachineState s) noexcept {
  return s == MachineState::kFault || s == MachineState::kEstop;
}

/// Alarm codes. Stable numbers: they travel over the bridge and into logs.
enum class AlarmCode : std::uint16_t {
  kNone = 0,
  kWatchdog = 100,         // task watchdog fault
  kWatchdogWarning = 101,  // task watchdog with action: warn
  kBlockFault = 110,       // a block's update() returned kFault
  kIoFault = 120,          // the I/O driver reported a fault
  kEstop = 130,            // emergency stop requested
  kFollowingError = 140,   // reserved: axis following error
  kSoftLimit = 141,        // reserved: soft-limit violation
  kShortCircuit = 150,     // reserved: sustained short circuit after N retracts
  kElectrodeUsedUp = 160,  // reserved: electrode length exhausted
  kWireBreak = 170,        // reserved: wire EDM wire break
};

std::string_view to_string(AlarmCode c) noexcept;

enum class AlarmSeverity : std::uint8_t { kWarning, kFault };

/// One alarm. Strings point to storage that lives as long as the runtime (names, literals).
struct Alarm {
  AlarmCode code{AlarmCode::kNone};
  AlarmSeverity severity{AlarmSeverity::kFault};
  TimePoint time{};
  const char* source{""};  // e.g. task or "program.block" name
  const char* text{""};    // static text
  double value{0.0};       // the measured quantity that tripped it (e.g. exec time in µs)
};

/// What a safe-state hook is told.
struct SafeStateRequest {
  MachineState state{MachineState::kFault};
  AlarmCode cause{AlarmCode::kNone};
};

/// Something that can put its part of the machine in a safe state: I/O drivers (generator off,
/// axes stopped at the drive) and programs (Z backed off, sequencers parked).
class SafeStateHandler {
 public:
  virtual ~SafeStateHandler() = default;
  /// Called once per entry into FAULT/ESTOP, from the owning task's RT thread. RT-safe.
  virtual void enter_safe_state(const SafeStateRequest& request) noexcept = 0;
};

enum class CommandResult : std::uint8_t { kOk, kInvalidState };

class Machine {
 public:
  static constexpr std::size_t kAlarmCapacity = 256;

  Machine() = default;
  Machine(const Machine&) = delete;
  Machine& operator=(const Machine&) = delete;

  [[nodiscard]] MachineState state() const noexcept {
    return state_.load(std::memory_order_acquire);
  }
  /// Applies an operator command if the current state allows it. Lock-free, any thread.
  CommandResult command(MachineCommand c, TimePoint now = {}) noexcept;
  /// Raises an alarm. A fault-severity alarm moves the machine to FAULT (unless in ESTOP or OFF).
  /// RT-safe. If the alarm queue is full the alarm is counted in dropped_alarms().
  void raise(const Alarm& a) noexcept;

  /// Increments on every entry into FAULT or ESTOP.
  [[nodiscard]] std::uint64_t safe_epoch() const noexcept {
    return safe_epoch_.load(std::memory_order_acquire);
  }
  /// The alarm that caused the last entry into a safe state.
  [[nodiscard]] AlarmCode last_cause() const noexcept {
    return last_cause_.load(std::memory_order_acquire);
  }
  /// Non-RT consumers (logger, bridge) pop alarms here.
  bool pop_alarm(Alarm& out) noexcept { return alarms_.pop(out); }
  [[nodiscard]] std::uint64_t dropped_alarms() const noexcept {
    return dropped_alarms_.load(std::memory_order_relaxed);
  }

 private:
  bool transition(MachineState from, MachineState to, AlarmCode cause) noexcept;

  std::atomic<MachineState> state_{MachineState::kOff};
  std::atomic<std::uint64_t> safe_epoch_{0};
  std::atomic<AlarmCode> last_cause_{AlarmCode::kNone};
  boost::lockfree::queue<Alarm, boost::lockfree::capacity<kAlarmCapacity>> alarms_;
  std::atomic<std::uint64_t> dropped_alarms_{0};
};

}  // namespace edm::rt
