// The session, program-transfer and machine-command ops (ops_handlers.hpp; docs/protocol.md),
// run on the server thread for one session.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <variant>

#include "edm/bridge/machine_info.hpp"
#include "edm/machining/program_check.hpp"
#include "edm/runtime/stats_json.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "ops_operator.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {

namespace {

constexpr std::size_t kMaxIssuesReported = 100;

/// hello's optional "peer" (a relaying HMI's end client): "" when absent, nullopt when invalid.
std::optional<std::string> hello_peer(const Json& msg) {
  const auto it = msg.find("peer");
  if (it == msg.end()) return std::string();
  if (!it->is_string() || !valid_hello_peer(it->get_ref<const std::string&>())) {
    return std::nullopt;
  }
  return it->get<std::string>();
}

Body op_machine(Session& s, rt::MachineCommand c, std::string_view op) {
  auto& m = s.server().rt.machine();
  const rt::MachineState before = m.state();
  // cycle.start's own checks (program loaded, referenced, offsets): ops::prepare_start().
  if (m.command(c) != rt::CommandResult::kOk) {
    return error(ErrorCode::kInvalidState,
                 std::string(op) + " is not allowed in " + std::string(to_string(before)));
  }
  return Json{{"state", std::string(to_string(m.state()))}};
}

}  // namespace

std::optional<SteadyClock::time_point> hello_wait(Session& s, const Json& msg) {
  const std::optional<std::string> via = hello_peer(msg);
  if (!via) return std::nullopt;
  const auto now = SteadyClock::now();
  const auto when = s.server().throttle.admit_at(s.peer_address(), *via, now);
  if (when > now) return when;
  return std::nullopt;
}

Body op_hello(Session& s, const Json& msg) {
  auto& srv = s.server();
  const std::optional<std::string> via = hello_peer(msg);
  if (!via) {
    return error(ErrorCode::kBadRequest, "'peer' must be 1 to " +
                                             std::to_string(kMaxHelloPeerChars) +
                                             " printable ASCII characters");
  }
  if (s.role()) {
    return error(ErrorCode::kInvalidState,
                 "hello already said (role " + std::string(to_string(*s.role())) + ")");
  }
  const Json* proto = field(msg, "protocol", [](const Json& j) { return j.is_number_integer(); });
  std::string token;
  if (auto it = msg.find("token"); it != msg.end() && it->is_string()) {
    token = it->get<std::string>();
  }
  std::optional<Role> role;
  if (proto != nullptr && proto->get<std::int64_t>() == kProtocolVersion) {
    role = authenticate(srv.tokens, token, s.loopback());
  }
  s.set_via(*via);
  if (!role) {
    srv.counters.hello_failures.fetch_add(1, std::memory_order_relaxed);
    const auto delay = srv.throttle.on_failure(s.peer_address(), *via, SteadyClock::now());
    std::string why = proto == nullptr || proto->get<std::int64_t>() != kProtocolVersion
                          ? "protocol version " + std::to_string(kProtocolVersion) + " required"
                      : !srv.tokens.any() ? "only loopback clients are served without a token"
                                          : "bad token";
    s.log(spdlog::level::warn, "hello refused: {} (next hello from this {} in {} ms)", why,
          via->empty() ? "address" : "peer", delay.count());
    return error(ErrorCode::kUnauthorized, std::move(why));
  }
  if (!srv.admit(s, *role)) {
    s.log(spdlog::level::info, "{} refused: every slot is taken", to_string(*role));
    return error(ErrorCode::kBusy, "too many sessions (max " +
                                       std::to_string(srv.opt.max_sessions) + ", " +
                                       std::to_string(kOperatorReserve) + " kept for an operator)");
  }
  s.set_role(*role);
  s.log(spdlog::level::info, "hello as {}{}", to_string(*role), s.loopback() ? "" : " (network)");
  return Json{{"role", std::string(to_string(*role))},
              {"protocol", kProtocolVersion},
              {"server", "edmplc"},
              {"session", s.id()},
              {"max_line_bytes", srv.opt.max_line_bytes},
              {"read_timeout_ms", srv.opt.read_timeout.count()}};
}

Body op_subscribe(Session& s, const Json& msg) {
  bool status = false;
  bool alarm = false;
  bool progress = false;
  const Json* topics = field(msg, "topics", [](const Json& j) { return j.is_array(); });
  if (topics == nullptr || topics->empty()) {
    return error(ErrorCode::kBadRequest, "'topics' must be a non-empty array");
  }
  for (const auto& t : *topics) {
    if (t == kTopicStatus) {
      status = true;
    } else if (t == kTopicAlarm) {
      alarm = true;
    } else if (t == kTopicProgress) {
      progress = true;
    } else {
      return error(ErrorCode::kBadRequest,
                   "unknown topic" +
                       (t.is_string() ? " " + brief_name(t.get_ref<const std::string&>()) : "") +
                       " (status, alarm, progress; traces: trace.start)");
    }
  }
  int rate = s.subscriptions().rate_hz > 0 ? s.subscriptions().rate_hz : 10;
  if (auto it = msg.find("rate_hz"); it != msg.end()) {
    if (!it->is_number_integer() || it->get<std::int64_t>() < kMinRateHz ||
        it->get<std::int64_t>() > kMaxRateHz) {
      return error(ErrorCode::kBadRequest, "'rate_hz' must be an integer 1..100");
    }
    rate = it->get<int>();
  }
  s.subscribe(status, alarm, progress, rate);
  const Session::Subscriptions now = s.subscriptions();
  Json subs = Json::array();
  for (auto [on, name] : {std::pair{now.status, kTopicStatus},
                          {now.alarm, kTopicAlarm},
                          {now.progress, kTopicProgress}}) {
    if (on) {
      subs.push_back(std::string(name));
    }
  }
  return Json{{"topics", std::move(subs)}, {"rate_hz", now.status ? now.rate_hz : 0}};
}

Body op_unsubscribe(Session& s, const Json& msg) {
  const Json* topics = field(msg, "topics", [](const Json& j) { return j.is_array(); });
  const bool all = topics == nullptr;
  auto drop = [&](std::string_view t) {
    return all || std::find(topics->begin(), topics->end(), Json(std::string(t))) != topics->end();
  };
  s.unsubscribe(drop(kTopicStatus), drop(kTopicAlarm), drop(kTopicProgress));
  return Json::object();
}

Body op_program_begin(Session& s, const Json& msg) {
  const Json* n = field(msg, "blocks", [](const Json& j) { return j.is_number_unsigned(); });
  if (n == nullptr || n->get<std::uint64_t>() == 0) {
    return error(ErrorCode::kBadRequest, "'blocks' must be the program's block count (> 0)");
  }
  if (n->get<std::uint64_t>() > kMaxProgramBlocks) {
    return error(ErrorCode::kTooLarge,
                 "a program has at most " + std::to_string(kMaxProgramBlocks) + " blocks");
  }
  static std::uint64_t next_upload = 1;
  Upload u;
  if (auto e = ops::read_upload_options(msg, u.slot, u.offsets_generation)) return *e;
  u.id = next_upload++;
  u.expected = n->get<std::size_t>();
  // Grown as chunks arrive: a one-line begin of 1,000,000 blocks must not take 150 MB at once.
  u.blocks.reserve(std::min<std::size_t>(u.expected, 4096));
  const Upload& now = s.begin_upload(std::move(u));
  return Json{{"upload", now.id}, {"blocks", now.expected}};
}

Body op_program_chunk(Session& s, const Json& msg) {
  if (s.upload() == nullptr) {
    return error(ErrorCode::kNotFound, "no upload in progress (program.begin first)");
  }
  Upload& u = *s.upload();
  const Json* first = field(msg, "first", [](const Json& j) { return j.is_number_unsigned(); });
  const Json* blocks = field(msg, "blocks", [](const Json& j) { return j.is_array(); });
  if (first == nullptr || blocks == nullptr) {
    return error(ErrorCode::kBadRequest,
                 "'first' (index of the chunk's first block) and 'blocks' (array) are required");
  }
  if (first->get<std::uint64_t>() != u.blocks.size()) {
    return error(ErrorCode::kBadRequest,
                 "chunk out of order: expected first = " + std::to_string(u.blocks.size()),
                 Json{{"expected_first", u.blocks.size()}});
  }
  if (u.blocks.size() + blocks->size() > u.expected) {
    return error(ErrorCode::kBadRequest, "more blocks than announced in program.begin (" +
                                             std::to_string(u.expected) + ")");
  }
  // Decode the whole chunk first: a bad chunk leaves the upload as it was (resend it).
  std::vector<machining::MotionBlock> decoded;
  std::string why;
  if (const auto bad = ops::decode_blocks(*blocks, decoded, why)) {
    const std::size_t index = u.blocks.size() + *bad;
    return error(ErrorCode::kBadRequest, "block " + std::to_string(index) + ": " + why,
                 Json{{"block", index}});
  }
  for (const auto& b : decoded) {
    u.crc.update(b);
    u.blocks.push_back(b);
  }
  return Json{{"received", u.blocks.size()}};
}

Body op_program_commit(Session& s, const Json& msg) {
  auto& srv = s.server();
  if (s.upload() == nullptr) {
    return error(ErrorCode::kNotFound, "no upload in progress (program.begin first)");
  }
  std::uint32_t want = 0;
  auto it = msg.find("checksum");
  if (it == msg.end() || !parse_checksum(*it, want)) {
    return error(ErrorCode::kBadRequest, "'checksum' must be 8 hex digits (CRC-32, see protocol)");
  }
  // The last job's end and figures, first: a load resets its progress (outcome, program).
  srv.note_job_end(srv.rt.job().progress());
  Upload& u = *s.upload();
  if (u.blocks.size() != u.expected) {
    return error(ErrorCode::kBadRequest, "incomplete program: " + std::to_string(u.blocks.size()) +
                                             " of " + std::to_string(u.expected) +
                                             " blocks received");
  }
  const std::uint32_t got = u.crc.value();
  if (got != want) {
    s.end_upload();
    return error(ErrorCode::kBadRequest, "checksum mismatch; upload discarded",
                 Json{{"expected", format_checksum(want)}, {"computed", format_checksum(got)}});
  }
  auto& rt = srv.rt;
  const rt::MachineState state = rt.machine().state();
  if (rt.job().active() || state == rt::MachineState::kRunning ||
      state == rt::MachineState::kHold) {
    return error(ErrorCode::kBusy, std::string("the machine is ") + std::string(to_string(state)) +
                                       "; a program is swapped in only when idle");
  }
  // The program starts where the machine is now.
  const machining::Vec3 start{rt.variables().read("io.x_mm").value_or(0.0),
                              rt.variables().read("io.y_mm").value_or(0.0),
                              rt.variables().read("io.z_mm").value_or(0.0)};
  machining::ProgramCheckOptions check;
  check.electrode_mm = rt.electrode().length_mm();
  const auto issues = machining::check_program(u.blocks, rt.tables(), start, check);
  if (!issues.empty()) {
    Json list = Json::array();
    for (std::size_t i = 0; i < issues.size() && i < kMaxIssuesReported; ++i) {
      const auto& is = issues[i];
      list.push_back(
          {{"block", is.block}, {"line", is.line}, {"col", is.col}, {"message", is.message}});
    }
    const auto& f = issues.front();
    std::string text =
        "line " + std::to_string(f.line) + ":" + std::to_string(f.col) + ": " + f.message;
    if (issues.size() > 1) {
      text += " (and " + std::to_string(issues.size() - 1) + " more)";
    }
    return error(ErrorCode::kBadRequest, text,
                 Json{{"issues", std::move(list)}, {"count", issues.size()}});
  }
  const std::size_t n = u.blocks.size();
  const rt::JobSlot slot = u.slot;
  const std::optional<std::uint64_t> offsets = u.offsets_generation;
  std::vector<machining::HoleWear> wear = machining::planned_wear(u.blocks, rt.tables());
  const rt::LoadResult loaded = slot == rt::JobSlot::kMdi ? rt.job().load_mdi(std::move(u.blocks))
                                                          : rt.job().load(std::move(u.blocks), got);
  if (loaded != rt::LoadResult::kOk) {
    s.end_upload();
    return error(ErrorCode::kBusy, "a job became active; program not swapped");
  }
  s.end_upload();
  srv.committed_offsets[static_cast<std::size_t>(slot)] = offsets;
  srv.committed_wear[static_cast<std::size_t>(slot)] = std::move(wear);
  srv.counters.programs_committed.fetch_add(1, std::memory_order_relaxed);
  s.log(spdlog::level::info, "committed {} of {} blocks (crc32 {})",
        slot == rt::JobSlot::kMdi ? "an MDI program" : "a program", n, format_checksum(got));
  return Json{{"blocks", n},
              {"slot", slot == rt::JobSlot::kMdi ? "mdi" : "main"},
              {"checksum", format_checksum(got)},
              {"generation", rt.job().progress().generation}};
}

Body op_tasks_stats(Session& s, const Json& /*msg*/) {
  auto& srv = s.server();
  Json doc = Json::parse(rt::stats_to_json(srv.rt.stats_reports()));
  const ServerStats st = srv.stats_snapshot();
  // Latched alarms and how often each repeated while latched (raised once, then counted).
  std::array<rt::ActiveAlarm, 64> latched{};
  const std::size_t n = srv.rt.machine().active_alarms(latched.data(), latched.size());
  Json active = Json::array();
  for (std::size_t i = 0; i < n; ++i) {
    active.push_back({{"code", static_cast<int>(latched[i].code)},
                      {"name", std::string(rt::to_string(latched[i].code))},
                      {"source", std::string(latched[i].source)},
                      {"first_t_s", rt::to_seconds(latched[i].first)},
                      {"count", latched[i].count}});
  }
  doc["alarms"] = {{"active", std::move(active)}, {"repeated", srv.rt.machine().repeated_alarms()}};
  doc["bridge"] = {{"sessions_open", st.sessions_open},
                   {"sessions_pending", st.sessions_pending},
                   {"pending_evicted", st.pending_evicted},
                   {"hello_timeouts", st.hello_timeouts},
                   {"hello_failures", st.hello_failures},
                   {"accept_errors", st.accept_errors},
                   {"queue_bytes_peak", st.queue_bytes_peak},
                   {"sessions_accepted", st.sessions_accepted},
                   {"sessions_refused", st.sessions_refused},
                   {"requests", st.requests},
                   {"errors", st.errors},
                   {"events_sent", st.events_sent},
                   {"events_dropped", st.events_dropped},
                   {"slow_disconnects", st.slow_disconnects},
                   {"timeouts", st.timeouts},
                   {"programs_committed", st.programs_committed}};
  return doc;
}

/// feed.override {percent: 0…150}: the machine's feed override (Machine::set_feed_override).
Body op_feed_override(Session& s, const Json& msg) {
  const auto it = msg.find("percent");
  if (it == msg.end() || !it->is_number()) {
    return error(ErrorCode::kBadRequest, "'percent' must be a number, 0 to 150");
  }
  const double pct = it->get<double>();
  if (!s.server().rt.machine().set_feed_override(pct / 100.0)) {
    return error(ErrorCode::kBadRequest, "'percent' must be in 0..150, got " + it->dump());
  }
  return Json{{"percent", pct}};
}

Body op_ping(Session& /*s*/, const Json& /*msg*/) { return Json{{"pong", true}}; }

Body op_status(Session& s, const Json& /*msg*/) {
  StatusMessage m = s.server().status_message();
  return to_json(m);
}

Body op_program_abort(Session& s, const Json& /*msg*/) {
  s.end_upload();
  return Json::object();
}

Body op_cycle_start(Session& s, const Json& msg) {
  if (auto e = prepare_start(s, msg)) return *e;
  s.server().note_job_end(s.server().rt.job().progress());  // the last job's figures, first
  return op_machine(s, rt::MachineCommand::kStart, "cycle.start");
}
Body op_cycle_hold(Session& s, const Json& /*msg*/) {
  return op_machine(s, rt::MachineCommand::kHold, "cycle.hold");
}
Body op_cycle_resume(Session& s, const Json& /*msg*/) {
  return op_machine(s, rt::MachineCommand::kResume, "cycle.resume");
}
Body op_cycle_stop(Session& s, const Json& /*msg*/) {
  return op_machine(s, rt::MachineCommand::kStop, "cycle.stop");
}
Body op_estop(Session& s, const Json& /*msg*/) {
  return op_machine(s, rt::MachineCommand::kEstop, "estop");
}
Body op_reset(Session& s, const Json& /*msg*/) {
  return op_machine(s, rt::MachineCommand::kReset, "reset");
}

Body op_machine_info(Session& s, const Json& /*msg*/) {
  rt::Runtime& rt = s.server().rt;
  Json info = to_json(rt.tables(), rt.config().machine.name);
  Json ops_list = Json::array();
  for (const OpSpec& o : op_table()) ops_list.push_back(std::string(o.name));
  info["ops"] = std::move(ops_list);
  info["manual"] = manual_info_json(rt.manual().info());
  info["condition_edit"] = rt.config().machine.condition_edit;
  return info;
}

}  // namespace edm::bridge::ops
