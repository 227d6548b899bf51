#include "edm/hmi/web_command.hpp"

#include <exception>

namespace edm::hmi {

namespace {

using bridge::Json;

Json bad_request(const std::string& message) {
  return {{"ok", false}, {"code", "bad_request"}, {"message", message}};
}

/// The blocking part of a command: the reply body.
Json run(PageBackend& b, const PageCommand& c, std::uint64_t owner) {
  switch (c.op) {
    case PageOp::kCheck: return b.check(c.text, c.name);
    case PageOp::kUpload: return b.upload(c.text, c.name);
    case PageOp::kStart: return b.start_job(c.dry_run);
    case PageOp::kStartFrom: return b.start_from(c.from_line, c.depth_done_mm, c.dry_run);
    case PageOp::kMdi: return b.mdi(c.mdi_line);
    case PageOp::kJogHold: return b.jog_hold(owner, c.axis, c.velocity_mm_s);
    case PageOp::kJogRelease: b.jog_release(owner); return {{"ok", true}};
    case PageOp::kJogStop: b.jog_stop_hold(); return b.relay("jog.stop", c.params);
    case PageOp::kTouch: return b.touch(c.target, c.set_frame);
    case PageOp::kOffsetSet: return b.offset_set(c.params);
    case PageOp::kAck: b.acknowledge(c.seq); return {{"ok", true}};
    case PageOp::kManualStatus:
    case PageOp::kOffsetGet: {
      const Json body = c.op == PageOp::kManualStatus ? b.manual_status() : b.offsets();
      return {{"ok", !body.is_null()}, {"body", body}};
    }
    case PageOp::kJob: return {{"ok", true}, {"body", b.job_snapshot()}};
    case PageOp::kStats: return b.stats();
    case PageOp::kQueue: return {{"ok", true}, {"body", b.queue_snapshot()}};
    case PageOp::kQueueAdd: {
      QueueItem item;
      item.part = c.name;
      item.text = c.text;
      item.repeat = c.repeat;
      item.step_x_mm = c.step_x_mm;
      item.step_y_mm = c.step_y_mm;
      return b.queue_add(item);
    }
    case PageOp::kQueueClear: return b.queue_control("clear");
    case PageOp::kQueueStart: return b.queue_control("start");
    case PageOp::kQueueStop: return b.queue_control("stop");
    case PageOp::kElectrodeMeasure: return b.electrode_measure(c.target, c.set_frame);
    case PageOp::kConditionSet: return b.condition_set(c.params);
    case PageOp::kCycleHold:
    case PageOp::kCycleResume:
    case PageOp::kCycleStop:
    case PageOp::kEstop:
    case PageOp::kReset:
    case PageOp::kFeedOverride:
    case PageOp::kHome:
    case PageOp::kJog:
    case PageOp::kVarList:
    case PageOp::kVarRead:
    case PageOp::kVarWrite:
    case PageOp::kVarForce:
    case PageOp::kVarUnforce:
    case PageOp::kElectrodeGet:
    case PageOp::kElectrodeChange:
    case PageOp::kJobsGet: return b.relay(page_op_info(c.op).name, c.params);
  }
  return bad_request("unknown command");
}

PageAction reply_action(Json reply) {
  PageAction a;
  a.kind = PageAction::Kind::kReply;
  a.reply = std::move(reply);
  return a;
}

PageAction action(std::string_view text, std::optional<bridge::Role> role) {
  PageMessage m = decode_page_message(text);
  if (auto* e = std::get_if<PageError>(&m)) {
    if (!role) {  // before the log-in only a log-in is taken
      PageAction a;
      a.kind = PageAction::Kind::kClose;
      a.reply = {{"t", "error"}, {"code", e->code}, {"message", "log in first: " + e->message}};
      return a;
    }
    if (e->is_command) return reply_action(page_refusal(e->id, e->code, e->message));
    return reply_action({{"t", "error"}, {"code", e->code}, {"message", e->message}});
  }
  if (auto* login = std::get_if<PageLogin>(&m)) {
    if (role)
      return reply_action(
          {{"t", "error"}, {"code", "bad_request"}, {"message", "already logged in"}});
    PageAction a;
    a.kind = PageAction::Kind::kLogin;
    a.token = std::move(login->token);
    return a;
  }
  if (!role) {
    PageAction a;
    a.kind = PageAction::Kind::kClose;
    a.reply = {{"t", "error"}, {"code", "unauthorized"}, {"message", "log in first"}};
    return a;
  }
  if (std::holds_alternative<PageHeld>(m)) {
    PageAction a;
    a.kind = PageAction::Kind::kHeld;
    return a;
  }
  PageCommand& c = std::get<PageCommand>(m);
  const PageOpInfo& info = page_op_info(c.op);
  if (*role != bridge::Role::kOperator && !info.viewer) {
    return reply_action(page_refusal(
        c.id, "forbidden", "'" + std::string(info.name) + "' needs the operator role", info.name));
  }
  PageAction a;
  a.kind = PageAction::Kind::kRun;
  a.command = std::move(c);
  return a;
}

}  // namespace

Json run_page_command(PageBackend& backend, const PageCommand& command,
                      std::uint64_t owner) noexcept {
  const std::string_view op = page_op_info(command.op).name;
  try {
    Json out = run(backend, command, owner);
    if (!out.is_object()) out = {{"ok", false}, {"code", "internal"}, {"message", "no reply"}};
    out["t"] = "reply";
    out["id"] = command.id;
    out["op"] = op;
    return out;
  } catch (const std::exception& e) {
    try {
      return page_refusal(command.id, "internal", std::string("internal error: ") + e.what(), op);
    } catch (...) {
    }
  } catch (...) {
    try {
      return page_refusal(command.id, "internal", "internal error", op);
    } catch (...) {
    }
  }
  return Json();  // only when even the refusal could not be allocated: the session sends nothing
}

PageAction page_action(std::string_view text, std::optional<bridge::Role> role) noexcept {
  try {
    return action(text, role);
  } catch (...) {
    try {
      return reply_action({{"t", "error"}, {"code", "internal"}, {"message", "internal error"}});
    } catch (...) {
      return PageAction{};
    }
  }
}

Json page_refusal(const Json& id, std::string_view code, std::string_view message,
                  std::string_view op) {
  Json r = {{"t", "reply"}, {"id", id}, {"ok", false}, {"code", code}, {"message", message}};
  if (!op.empty()) r["op"] = op;
  return r;
}

std::string page_text(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace edm::hmi
