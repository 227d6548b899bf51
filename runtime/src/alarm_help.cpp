#include "edm/runtime/alarm_help.hpp"

namespace edm::rt {

AlarmHelp alarm_help(AlarmCode code) noexcept {
  switch (code) {
    case AlarmCode::kNone: return {};
    case AlarmCode::kWatchdog:
      return {
          "a task's cycle took longer than its watchdog time: the machine cannot be "
          "trusted to react in time",
          "see `edmhmi stats` for the task's execution time; lower the load on the host "
          "(or the task's work), then reset"};
    case AlarmCode::kWatchdogWarning:
      return {"a task's cycle took longer than its watchdog time (the task is set to warn)",
              "see `edmhmi stats`; if it repeats, lower the host's load or raise the watchdog"};
    case AlarmCode::kHostStall:
      return {
          "the host stopped the process for longer than the watchdog time (the cycle's "
          "own work was within it)",
          "look for swapping, a busy host or a missing real-time setup (docs/runtime.md, the "
          "real-time environment)"};
    case AlarmCode::kBlockFault:
      return {"a block reported a fault: the alarm's source names the block and its text why",
              "check the block's inputs in the Variables tab (a lost wire, a forced value, a "
              "parameter out of its range); correct it, then reset"};
    case AlarmCode::kIoFault:
      return {"the I/O driver reported a fault (a drive, the generator or the simulator)",
              "check the drive and the generator, their cables and power; then reset"};
    case AlarmCode::kIoStale:
      return {
          "a field-bus image is older than its stale_cycles limit, or the HAL side's "
          "heartbeat stopped: the remote I/O or the HAL component (a card's driver, "
          "edm-sim-hal) stopped answering (the value is the age in cycles)",
          "check the remote I/O's power and network cable, or the HAL session (halcmd show "
          "comp); reset once it answers again"};
    case AlarmCode::kEstop:
      return {"the emergency stop was pressed or requested",
              "make the machine safe, release the E-stop, then reset"};
    case AlarmCode::kInterlockOpen:
      return {"a safety interlock (the door switch) is open",
              "close the door or guard, then reset"};
    case AlarmCode::kFollowingError:
      return {
          "an axis lags its command by more than its following-error limit: jammed, "
          "blocked or its drive off (the value is the error in mm)",
          "check the axis for a collision or a jam and its drive for a fault; then reset "
          "and reference it again"};
    case AlarmCode::kSoftLimit:
      return {
          "an axis was commanded, or is, outside its soft limits (the value is the "
          "position or speed)",
          "check the work offset and the program's coordinates; jog the axis back into "
          "its range, then reset"};
    case AlarmCode::kShortCircuit:
      return {
          "the short circuit persisted after every retract the job allows: debris or a "
          "touching electrode",
          "raise Z, check and flush the gap (flushing pressure, debris), then reset and "
          "run the part from the block"};
    case AlarmCode::kElectrodeUsedUp:
      return {"the electrode's length left is at its margin (the value is the length in mm)",
              "change the electrode, measure it and set its length (`edmhmi electrode set MM`), "
              "then reset"};
    case AlarmCode::kWireBreak:
      return {"the wire broke", "rethread the wire, then reset and resume the cut"};
    case AlarmCode::kRetainCorrupt:
      return {
          "the retain file could not be read: it was set aside and defaults are in use "
          "(offsets, the electrode length, counters)",
          "check the work offsets and the electrode length before running, then reset; the "
          "old file is kept beside the new one"};
    case AlarmCode::kForcesReleased:
      return {"a safe state released forced pins (the value is how many)",
              "force them again if still needed, once the machine is safe"};
    case AlarmCode::kJobInterrupted:
      return {
          "the machine stopped uncleanly while a job ran (the text names the program, "
          "block, line and depth)",
          "reset, then run the part from the named line (`edmhmi run --from LINE`)"};
    case AlarmCode::kRetainWriteFailed:
      return {
          "the retain file could not be written (a full disk or a read-only state "
          "directory; the value counts the failures)",
          "free space in the state directory or make it writable; the alarm clears at the "
          "next good write"};
  }
  return {};
}

std::span<const AlarmCode> all_alarm_codes() noexcept {
  static constexpr AlarmCode kAll[] = {
      AlarmCode::kWatchdog,       AlarmCode::kWatchdogWarning,  AlarmCode::kHostStall,
      AlarmCode::kBlockFault,     AlarmCode::kIoFault,          AlarmCode::kIoStale,
      AlarmCode::kEstop,          AlarmCode::kInterlockOpen,    AlarmCode::kFollowingError,
      AlarmCode::kSoftLimit,      AlarmCode::kShortCircuit,     AlarmCode::kElectrodeUsedUp,
      AlarmCode::kWireBreak,      AlarmCode::kRetainCorrupt,    AlarmCode::kForcesReleased,
      AlarmCode::kJobInterrupted, AlarmCode::kRetainWriteFailed};
  return kAll;
}

}  // namespace edm::rt
