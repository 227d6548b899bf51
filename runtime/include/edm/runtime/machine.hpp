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
// Alarms are latched (DESIGN §11: raised once per occurrence, then counted): the first raise()
// of a (code, source) pair is queued for the log and the bridge; raising it again while it is
// latched only counts (ActiveAlarm::count, repeated_alarms()). The latch opens when the raiser
// says the condition is gone (clear_alarm) or at reset, whichever comes first; the next raise
// after that is a new occurrence. A raiser that never calls clear_alarm gets one alarm per reset.
//
// Thread-safety: every member is lock-free and may be called from any thread, RT included.

#include <array>
#include <atomic>
#include <cstdint>
#include <string_view>

#include "edm/runtime/mpmc_queue.hpp"
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
  kHostStall = 102,        // warning: a cycle over its watchdog time because the host stalled
  kBlockFault = 110,       // a block's update() returned kFault
  kIoFault = 120,          // the I/O driver reported a fault
  kIoStale = 121,          // a field-bus driver's process image is too old (value: age, cycles)
  kEstop = 130,            // emergency stop requested
  kInterlockOpen = 131,    // a safety interlock input (door switch) is open
  kFollowingError = 140,   // axis following error (safety supervisor)
  kSoftLimit = 141,        // soft limit: command refused or axis outside (safety supervisor)
  kShortCircuit = 150,     // reserved: sustained short circuit after N retracts
  kElectrodeUsedUp = 160,  // electrode length at its margin (safety supervisor)
  kWireBreak = 170,        // wire EDM wire break (safety supervisor)
  kRetainCorrupt = 180,    // the retain file could not be read: set aside, defaults in use
  kForcesReleased = 181,   // a safe state released forced pins (value: how many)
  kJobInterrupted = 182,   // the retain file shows a job running at an unclean stop (value: depth)
  kRetainWriteFailed = 183,  // warning: the retain file could not be written (value: failures)
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

/// A latched alarm: the first occurrence's record and how many times it was raised since.
struct ActiveAlarm {
  AlarmCode code{AlarmCode::kNone};
  const char* source{""};
  TimePoint first{};       // release time of the cycle that first raised it
  std::uint64_t count{0};  // raises while latched, the first included
  const char* text{""};    // the first occurrence's text (why) and value
  double value{0.0};
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
  /// Distinct alarms latched at once; beyond that a raise is queued unlatched (never lost).
  static constexpr std::size_t kLatchCapacity = 64;

  Machine() = default;
  Machine(const Machine&) = delete;
  Machine& operator=(const Machine&) = delete;

  [[nodiscard]] MachineState state() const noexcept {
    return state_.load(std::memory_order_acquire);
  }
  /// Applies an operator command if the current state allows it. Lock-free, any thread.
  /// `now` stamps the E-stop alarm; the default (zero) means "the latest cycle's release time"
  /// (callers off the RT threads, e.g. the bridge, have no cycle time of their own). Reset
  /// opens every alarm latch.
  CommandResult command(MachineCommand c, TimePoint now = {}) noexcept;
  /// Raises an alarm. A fault-severity alarm moves the machine to FAULT (unless in ESTOP or OFF),
  /// also when it is a repeat. Returns true for a new occurrence (queued; counted in
  /// dropped_alarms() if the queue is full), false for a repeat of a latched one (only
  /// counted). A zero a.time is stamped with the latest cycle's release time. RT-safe.
  bool raise(const Alarm& a) noexcept;
  /// The raiser's condition is gone: the next raise of (code, source) is a new occurrence.
  /// Sources compare by text. RT-safe; a no-op when nothing is latched.
  void clear_alarm(AlarmCode code, const char* source) noexcept;
  /// Copies the latched alarms into `out` (at most out.size()); returns how many. Non-RT
  /// readers (status, tests); a snapshot, racing benignly with raisers.
  std::size_t active_alarms(ActiveAlarm* out, std::size_t capacity) const noexcept;
  /// Raises that were repeats of a latched alarm (not queued), since start.
  [[nodiscard]] std::uint64_t repeated_alarms() const noexcept {
    return repeated_alarms_.load(std::memory_order_relaxed);
  }
  /// Tasks publish each cycle's release time (the last writer wins). RT-safe.
  void note_release(TimePoint release) noexcept;
  [[nodiscard]] TimePoint last_release() const noexcept {
    return TimePoint{last_release_ns_.load(std::memory_order_relaxed)};
  }

  /// Increments on every entry into FAULT or ESTOP.
  [[nodiscard]] std::uint64_t safe_epoch() const noexcept {
    return safe_epoch_.load(std::memory_order_acquire);
  }
  /// The alarm that caused the last entry into a safe state.
  [[nodiscard]] AlarmCode last_cause() const noexcept {
    return last_cause_.load(std::memory_order_acquire);
  }
  /// The operator's feed override (issue 21): 0 … kMaxFeedOverride, 1 = as programmed. A job
  /// sequencer scales its rapids, feeds, orbit feed and the gap-controlled downward feed cap by
  /// it (never a retract). Any thread; a value outside [0, kMaxFeedOverride] or not finite is
  /// refused (false) and changes nothing.
  static constexpr double kMaxFeedOverride = 1.5;
  bool set_feed_override(double ratio) noexcept;
  /// RT-safe.
  [[nodiscard]] double feed_override() const noexcept {
    return feed_override_.load(std::memory_order_relaxed);
  }

  /// Non-RT consumers (logger, bridge) pop alarms here.
  bool pop_alarm(Alarm& out) noexcept { return alarms_.pop(out); }
  [[nodiscard]] std::uint64_t dropped_alarms() const noexcept {
    return dropped_alarms_.load(std::memory_order_relaxed);
  }

 private:
  bool transition(MachineState from, MachineState to, AlarmCode cause) noexcept;
  void enter_fault(AlarmCode cause) noexcept;
  void clear_all_latches() noexcept;

  // state: 0 free, 1 being filled, 2 latched. code/source/first are written only in state 1.
  struct Latch {
    std::atomic<std::uint32_t> state{0};
    std::atomic<AlarmCode> code{AlarmCode::kNone};
    std::atomic<const char*> source{""};
    std::atomic<Duration::rep> first_ns{0};
    std::atomic<std::uint64_t> count{0};
    std::atomic<const char*> text{""};
    std::atomic<double> value{0.0};
  };

  std::atomic<MachineState> state_{MachineState::kOff};
  std::atomic<std::uint64_t> safe_epoch_{0};
  std::atomic<AlarmCode> last_cause_{AlarmCode::kNone};
  MpmcQueue<Alarm, kAlarmCapacity> alarms_;
  std::atomic<std::uint64_t> dropped_alarms_{0};
  std::array<Latch, kLatchCapacity> latches_{};
  std::atomic<std::uint64_t> repeated_alarms_{0};
  std::atomic<Duration::rep> last_release_ns_{0};
  std::atomic<double> feed_override_{1.0};
};

}  // namespace edm::rt
