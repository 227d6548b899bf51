#include "edm/bridge/op_states.hpp"

#include <array>

#include "edm/runtime/runtime.hpp"

namespace edm::bridge {
namespace {

using S = OpState;

constexpr StateMask operator|(S a, S b) noexcept { return mask_of(a) | mask_of(b); }
constexpr StateMask operator|(StateMask a, S b) noexcept { return a | mask_of(b); }

constexpr StateMask kAll = (1U << kOpStateCount) - 1;
constexpr StateMask kNotDuringAJob = kAll & ~(S::kRunning | S::kHold);
constexpr StateMask kNotInASafeState = kAll & ~(S::kFault | S::kEstop);

// The table. Manual motion runs only from an idle READY machine, one operation at a time (a
// continuous jog is refreshed, or changes speed or axis, by another jog with a velocity); a job
// starts only from there too. A stop or an E-stop is never refused.
constexpr std::array<OpStateRule, 33> kRules = {{
    {"hello", "", kAll},
    {"ping", "", kAll},
    {"status", "", kAll},
    {"subscribe", "", kAll},
    {"unsubscribe", "", kAll},
    {"program.begin", "", kAll},
    {"program.chunk", "", kAll},
    {"program.commit", "", kNotDuringAJob},
    {"program.abort", "", kAll},
    {"cycle.start", "", mask_of(S::kIdle)},
    {"cycle.hold", "", mask_of(S::kRunning)},
    {"cycle.resume", "", mask_of(S::kHold)},
    {"cycle.stop", "", S::kRunning | S::kHold},
    {"estop", "", kAll},
    {"reset", "", S::kFault | S::kEstop},
    {"var.list", "", kAll},
    {"var.read", "", kAll},
    {"var.write", "", kAll},
    {"var.force", "", kNotInASafeState},
    {"var.unforce", "", kAll},
    {"tasks.stats", "", kAll},
    {"trace.start", "", kAll},
    {"trace.stop", "", kAll},
    {"machine.info", "", kAll},
    {"feed.override", "", kAll},
    {"home", "", mask_of(S::kIdle)},
    {"jog", "velocity", S::kIdle | S::kJogging},
    {"jog", "distance", mask_of(S::kIdle)},
    {"jog.stop", "", kAll},
    {"touch", "", mask_of(S::kIdle)},
    {"manual.status", "", kAll},
    {"offset.get", "", kAll},
    {"offset.set", "", kNotDuringAJob},
}};

}  // namespace

std::string_view to_string(OpState s) noexcept {
  switch (s) {
    case S::kOff:
      return "OFF";
    case S::kIdle:
      return "READY";
    case S::kJogging:
      return "READY with a continuous jog running";
    case S::kManual:
      return "READY with a manual operation running";
    case S::kRunning:
      return "RUNNING";
    case S::kHold:
      return "HOLD";
    case S::kFault:
      return "FAULT";
    case S::kEstop:
      return "ESTOP";
  }
  return "?";
}

std::span<const OpStateRule> op_state_rules() noexcept { return kRules; }

const OpStateRule* op_state_rule(std::string_view op, const Json& msg) noexcept {
  // jog's kind: a velocity makes it continuous; anything else is judged as a distance (a request
  // with neither or both is then refused bad_request by the op itself, where the state allows).
  const std::string_view variant =
      op != "jog" ? "" : (msg.is_object() && msg.contains("velocity") ? "velocity" : "distance");
  for (const OpStateRule& r : kRules) {
    if (r.op == op && r.variant == variant) return &r;
  }
  return nullptr;
}

OpState current_op_state(rt::Runtime& rt) noexcept {
  switch (rt.machine().state()) {
    case rt::MachineState::kOff:
      return S::kOff;
    case rt::MachineState::kRunning:
      return S::kRunning;
    case rt::MachineState::kHold:
      return S::kHold;
    case rt::MachineState::kFault:
      return S::kFault;
    case rt::MachineState::kEstop:
      return S::kEstop;
    case rt::MachineState::kReady:
      break;
  }
  if (rt.job().active()) return S::kRunning;
  switch (rt.manual().activity()) {
    case rt::ManualOp::kNone:
    case rt::ManualOp::kStop:
      return S::kIdle;
    case rt::ManualOp::kJogVelocity:
      return S::kJogging;
    case rt::ManualOp::kHome:
    case rt::ManualOp::kJogDistance:
    case rt::ManualOp::kTouch:
      break;
  }
  return S::kManual;
}

}  // namespace edm::bridge
