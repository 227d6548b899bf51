// The op table (op_table.hpp) and the one dispatch that uses it, run_op().
#include "edm/bridge/op_table.hpp"

#include <variant>

#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge {
namespace {

using S = OpState;

constexpr StateMask operator|(S a, S b) noexcept { return mask_of(a) | mask_of(b); }
constexpr StateMask operator|(StateMask a, S b) noexcept { return a | mask_of(b); }

constexpr StateMask kAll = (1U << kOpStateCount) - 1;
constexpr StateMask kNotDuringAJob = kAll & ~(S::kRunning | S::kHold);
constexpr StateMask kNotInASafeState = kAll & ~(S::kFault | S::kEstop);

/// One kind of an op, allowed in `m`.
constexpr OpKind states(StateMask m) noexcept { return OpKind{"", m}; }

constexpr auto kBefore = OpAccess::kBeforeHello;
constexpr auto kView = OpAccess::kViewer;
constexpr auto kOper = OpAccess::kOperator;

// The table. Manual motion runs only from an idle READY machine, one operation at a time (a
// continuous jog is refreshed, or changes speed or axis, by another jog with a velocity); a job
// starts only from there too. A stop or an E-stop is never refused.
constexpr OpSpec kOps[] = {
    {"hello", kBefore, states(kAll), ops::op_hello},
    {"ping", kView, states(kAll), ops::op_ping},
    {"status", kView, states(kAll), ops::op_status},
    {"subscribe", kView, states(kAll), ops::op_subscribe},
    {"unsubscribe", kView, states(kAll), ops::op_unsubscribe},
    {"program.begin", kOper, states(kAll), ops::op_program_begin},
    {"program.chunk", kOper, states(kAll), ops::op_program_chunk},
    {"program.commit", kOper, states(kNotDuringAJob), ops::op_program_commit},
    {"program.abort", kOper, states(kAll), ops::op_program_abort},
    {"cycle.start", kOper, states(mask_of(S::kIdle)), ops::op_cycle_start},
    {"cycle.hold", kOper, states(mask_of(S::kRunning)), ops::op_cycle_hold},
    {"cycle.resume", kOper, states(mask_of(S::kHold)), ops::op_cycle_resume},
    {"cycle.stop", kOper, states(S::kRunning | S::kHold), ops::op_cycle_stop},
    {"estop", kOper, states(kAll), ops::op_estop},
    {"reset", kOper, states(S::kFault | S::kEstop), ops::op_reset},
    {"var.list", kView, states(kAll), ops::op_var_list},
    {"var.read", kView, states(kAll), ops::op_var_read},
    {"var.write", kOper, states(kAll), ops::op_var_write},
    {"var.force", kOper, states(kNotInASafeState), ops::op_var_force},
    {"var.unforce", kOper, states(kAll), ops::op_var_unforce},
    {"tasks.stats", kView, states(kAll), ops::op_tasks_stats},
    {"trace.start", kView, states(kAll), ops::op_trace_start},
    {"trace.stop", kView, states(kAll), ops::op_trace_stop},
    {"machine.info", kView, states(kAll), ops::op_machine_info},
    {"feed.override", kOper, states(kAll), ops::op_feed_override},
    {"home", kOper, states(mask_of(S::kIdle)), ops::op_home},
    {"jog",
     kOper,
     {"distance", mask_of(S::kIdle)},
     ops::op_jog,
     "velocity",
     {"velocity", S::kIdle | S::kJogging}},
    {"jog.stop", kOper, states(kAll), ops::op_jog_stop},
    {"touch", kOper, states(mask_of(S::kIdle)), ops::op_touch},
    {"manual.status", kView, states(kAll), ops::op_manual_status},
    {"offset.get", kView, states(kAll), ops::op_offset_get},
    {"offset.set", kOper, states(kNotDuringAJob), ops::op_offset_set},
    {"electrode.get", kView, states(kAll), ops::op_electrode_get},
    {"electrode.set", kOper, states(kNotDuringAJob), ops::op_electrode_set},
    {"electrode.change", kOper, states(mask_of(S::kIdle)), ops::op_electrode_change},
    {"electrode.measure", kOper, states(mask_of(S::kIdle)), ops::op_electrode_measure},
    {"alarms.get", kView, states(kAll), ops::op_alarms_get},
    {"jobs.get", kView, states(kAll), ops::op_jobs_get},
    {"condition.set", kOper, states(mask_of(S::kIdle)), ops::op_condition_set},
};

// A row without a handler, or a name twice, does not compile.
constexpr bool every_row_has_a_handler_and_its_own_name() {
  for (std::size_t i = 0; i < std::size(kOps); ++i) {
    if (kOps[i].handler == nullptr || kOps[i].name.empty()) return false;
    if (kOps[i].kind_field.empty() != kOps[i].field_kind.name.empty()) return false;
    for (std::size_t j = 0; j < i; ++j) {
      if (kOps[j].name == kOps[i].name) return false;
    }
  }
  return true;
}
static_assert(every_row_has_a_handler_and_its_own_name());

/// What an audit entry says about a request beyond its op: the variable and value, the frame,
/// the program's checksum. Short, one line: every client-supplied part is escaped and cut.
std::string audit_detail(const std::string& op, const Json& msg) {
  std::string d;
  const auto add = [&d](std::string_view key, std::string_view text) {
    if (!d.empty()) d += ' ';
    d += key;
    d += '=';
    d += text;
  };
  for (const char* key :
       {"name", "frame", "axis", "axes", "target", "slot", "electrode", "reference"}) {
    if (auto it = msg.find(key); it != msg.end() && it->is_string()) {
      add(key, ops::brief_name(it->get_ref<const std::string&>()));
    }
  }
  for (const char* key : {"value", "distance", "velocity", "percent", "x", "y", "z", "length_mm"}) {
    if (auto it = msg.find(key); it != msg.end() && it->is_primitive()) {
      // A number, boolean or null dumps as plain ASCII; a string is quoted and escaped.
      add(key, it->is_string() ? ops::brief_name(it->get_ref<const std::string&>())
                               : it->dump().substr(0, 32));
    }
  }
  if (op == "program.commit") {
    if (auto it = msg.find("checksum"); it != msg.end() && it->is_string()) {
      d = "checksum=" + ops::brief_name(it->get_ref<const std::string&>());
    }
  }
  return d;
}

/// The row's refusal of this request in the machine's state now, or nullopt: it may run.
std::optional<ops::Body> refuse_in_state(Session& s, const OpSpec& op, const ParsedRequest& req) {
  const OpKind& kind = op_kind(op, req.msg);
  const OpState state = current_op_state(s.server().rt);
  if (allowed_in(kind, state)) return std::nullopt;
  const std::string what =
      kind.name.empty() ? req.op : req.op + " (" + std::string(kind.name) + ")";
  return ops::error(ErrorCode::kInvalidState,
                    what + " is not allowed in " + std::string(to_string(state)));
}

}  // namespace

std::string_view to_string(OpState s) noexcept {
  switch (s) {
    case S::kOff: return "OFF";
    case S::kIdle: return "READY";
    case S::kJogging: return "READY with a continuous jog running";
    case S::kManual: return "READY with a manual operation running";
    case S::kRunning: return "RUNNING";
    case S::kHold: return "HOLD";
    case S::kFault: return "FAULT";
    case S::kEstop: return "ESTOP";
  }
  return "?";
}

std::span<const OpSpec> op_table() noexcept { return kOps; }

const OpSpec* find_op(std::string_view name) noexcept {
  for (const OpSpec& op : kOps) {
    if (op.name == name) return &op;
  }
  return nullptr;
}

const OpKind& op_kind(const OpSpec& op, const Json& msg) noexcept {
  if (!op.kind_field.empty() && msg.is_object() && msg.contains(op.kind_field)) {
    return op.field_kind;
  }
  return op.kind;
}

OpState current_op_state(rt::Runtime& rt) noexcept {
  switch (rt.machine().state()) {
    case rt::MachineState::kOff: return S::kOff;
    case rt::MachineState::kRunning: return S::kRunning;
    case rt::MachineState::kHold: return S::kHold;
    case rt::MachineState::kFault: return S::kFault;
    case rt::MachineState::kEstop: return S::kEstop;
    case rt::MachineState::kReady: break;
  }
  if (rt.job().active()) return S::kRunning;
  switch (rt.manual().activity()) {
    case rt::ManualOp::kNone:
    case rt::ManualOp::kStop: return S::kIdle;
    case rt::ManualOp::kJogVelocity: return S::kJogging;
    case rt::ManualOp::kHome:
    case rt::ManualOp::kJogDistance:
    case rt::ManualOp::kTouch: break;
  }
  return S::kManual;
}

OpResult run_op(Session& s, const ParsedRequest& req) {
  OpResult r;
  const OpSpec* op = find_op(req.op);
  ops::Body body;
  if (op == nullptr) {
    body = ops::error(ErrorCode::kUnknownOp, "unknown op " + ops::brief_name(req.op));
  } else if (op->access == OpAccess::kBeforeHello) {
    if (!s.role()) {
      if (const auto when = ops::hello_wait(s, req.msg)) {
        r.retry_at = *when;  // evaluated later: the failed-hello throttle
        return r;
      }
    }
    body = op->handler(s, req.msg);
    r.close_after = std::holds_alternative<ops::Error>(body) && !s.role();  // refused: it ends
  } else if (!s.role()) {
    body = ops::error(ErrorCode::kUnauthorized, "hello first");
  } else if (op->access == OpAccess::kOperator && *s.role() != Role::kOperator) {
    body = ops::error(ErrorCode::kForbidden, "'" + req.op + "' needs the operator role");
  } else if (auto refusal = refuse_in_state(s, *op, req)) {
    body = std::move(*refusal);
  } else {
    body = op->handler(s, req.msg);
  }
  const auto* e = std::get_if<ops::Error>(&body);
  if (op != nullptr && op->access == OpAccess::kOperator && s.role()) {
    const std::string detail = audit_detail(req.op, req.msg);
    s.server().audit.record({.session = s.id(),
                             .role = to_string(*s.role()),
                             .peer = s.peer(),
                             .address = s.peer_address(),
                             .via = s.via(),
                             .op = req.op,
                             .detail = detail,
                             .outcome = e != nullptr ? to_string(e->code) : "ok"},
                            s.server().log_limiter);
  }
  if (e != nullptr) {
    r.reply = make_error(req.id, e->code, e->message, e->details);
  } else {
    r.reply = make_reply(req.id, std::get<Json>(body));
  }
  return r;
}

}  // namespace edm::bridge
