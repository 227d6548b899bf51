#pragma once
// The bridge's one op table: for every op of the protocol its name, the least role that may run
// it, the machine states it may run in and its handler, in one row (docs/protocol.md "Op states",
// "Authentication and roles"). run_op() finds a request's row and checks, in this order: the
// op exists (unknown_op), hello said (unauthorized), the role (forbidden), the state
// (invalid_state, nothing changes); then it calls the row's handler. Nothing else lists ops:
// machine.info's "ops" is this table, and tests/bridge/op_table_test.cpp checks it against
// docs/protocol.md.
//
// The state is what the machine is doing, with the manual motion's activity — what runs *or is
// already sent* (rt::ManualControl::activity()), so a touch sent in the same write as a jog is
// refused although the jog has not started yet. The runtime keeps its own guards for races (the
// machine's transition table, ManualMotion's busy guard); the table says the same, earlier.
//
// Thread-safety: the table is constant data (any thread). Handlers and current_op_state() run on
// the server thread only (they read the runtime through its thread-safe non-RT API).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "edm/bridge/codec.hpp"
#include "edm/bridge/protocol.hpp"

namespace edm::rt {
class Runtime;
}

namespace edm::bridge {

class Session;  // the server's session (server-internal)

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

/// What the machine is doing now.
OpState current_op_state(rt::Runtime& rt) noexcept;

namespace ops {
/// A refused request: the reply's error code, message and optional details.
struct Error {
  ErrorCode code;
  std::string message;
  Json details{nullptr};
};
/// What a handler returns: the reply body, or an error.
using Body = std::variant<Json, Error>;
}  // namespace ops

/// Runs one op for a session once every check passed (server thread).
using OpHandler = ops::Body (*)(Session& s, const Json& msg);

/// Who may run an op: before hello (hello only), every role, or the operator only.
enum class OpAccess : std::uint8_t { kBeforeHello, kViewer, kOperator };

/// The states one kind of an op may run in. `name` is "" for an op with one kind.
struct OpKind {
  std::string_view name;
  StateMask allowed;
};

/// One row of the table.
struct OpSpec {
  std::string_view name;
  OpAccess access;
  OpKind kind;  // the states (jog: of a request without `kind_field`, "distance")
  OpHandler handler;
  std::string_view kind_field{};  // jog: a request with this field ("velocity") is of field_kind
  OpKind field_kind{};
};

/// Every op, in protocol order.
std::span<const OpSpec> op_table() noexcept;
/// The row of `name`, or nullptr when the protocol has no such op.
const OpSpec* find_op(std::string_view name) noexcept;
/// The kind that judges this request: a request with the row's kind field is of its field kind
/// (a jog with a velocity is continuous); anything else is of the row's kind (a request with
/// neither or both is then refused bad_request by the handler, where the state allows).
[[nodiscard]] const OpKind& op_kind(const OpSpec& op, const Json& msg) noexcept;
[[nodiscard]] constexpr bool allowed_in(const OpKind& k, OpState s) noexcept {
  return (k.allowed & mask_of(s)) != 0;
}

}  // namespace edm::bridge
