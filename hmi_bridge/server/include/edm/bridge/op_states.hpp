#pragma once
// The states each op may run in (docs/protocol.md "Op states"): ONE table for every op of the
// protocol, checked in run_op() before an op runs; a request outside its states is refused
// `invalid_state` and changes nothing. The runtime keeps its own guards for races (the machine's
// transition table, ManualMotion's busy guard); the table says the same, earlier, for the client.
//
// The state is what the machine is doing, with the manual motion's activity — what runs *or is
// already sent* (rt::ManualControl::activity()), so a touch sent in the same write as a jog is
// refused although the jog has not started yet.
//
// Server thread only (reads the runtime through its thread-safe non-RT API).

#include <cstdint>
#include <span>
#include <string_view>

#include "edm/bridge/codec.hpp"

namespace edm::rt {
class Runtime;
}

namespace edm::bridge {

enum class OpState : std::uint8_t {
  kOff,      // OFF
  kIdle,     // READY: no job, no manual operation
  kJogging,  // READY: a continuous jog runs or was sent (refreshed by jog with a velocity)
  kManual,   // READY: another manual operation runs or was sent (incremental jog, home, touch)
  kRunning,  // RUNNING, or READY while a job is still active (ending)
  kHold,     // HOLD
  kFault,    // FAULT
  kEstop,    // ESTOP
};
inline constexpr int kOpStateCount = 8;
using StateMask = std::uint16_t;

/// "OFF", "READY", "READY with a continuous jog running", …, "RUNNING", "HOLD", "FAULT", "ESTOP".
std::string_view to_string(OpState s) noexcept;
constexpr StateMask mask_of(OpState s) noexcept { return static_cast<StateMask>(1U << int(s)); }

/// One row of the table: an op (jog: by its kind, "velocity" or "distance") and its states.
struct OpStateRule {
  std::string_view op;
  std::string_view variant;  // "" for every op but jog
  StateMask allowed;
};
/// Every row, in protocol order; every op of all_ops() has at least one.
std::span<const OpStateRule> op_state_rules() noexcept;
/// The row that judges this request, or nullptr for an unknown op.
const OpStateRule* op_state_rule(std::string_view op, const Json& msg) noexcept;
[[nodiscard]] constexpr bool allowed_in(const OpStateRule& r, OpState s) noexcept {
  return (r.allowed & mask_of(s)) != 0;
}

/// What the machine is doing now.
OpState current_op_state(rt::Runtime& rt) noexcept;

}  // namespace edm::bridge
