// The operator functions' ops (ops_handlers.hpp; docs/protocol.md "Operator functions"):
//   home, jog, jog.stop, touch, manual.status   → rt::ManualControl (the runtime's ManualMotion)
// (offset.* and electrode.*: ops_offsets.cpp)
#include "ops_operator.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {
namespace {

/// The program's planned wear against the electrode left (the estimate less the supervisor's
/// margin, alarm 160): a refusal naming the first hole the electrode could not finish, or nullopt
/// (it suffices, or its length is unknown). A machine stops before a hole it cannot finish.
std::optional<Body> electrode_too_short(rt::Runtime& rt,
                                        const std::vector<machining::HoleWear>& holes) {
  const double length = rt.electrode().length_mm();
  if (!(length > 0.0) || holes.empty()) return std::nullopt;
  const double margin = rt.config().machine.safety.electrode_margin_mm;
  const double usable = length - margin;
  for (const machining::HoleWear& h : holes) {
    if (h.cumulative_mm <= usable) continue;
    char text[320];
    std::snprintf(text, sizeof text,
                  "the electrode would run out in the hole of line %d: the program wears an "
                  "estimated %.3f mm by its end, %.3f mm through that hole; %.3f mm of the "
                  "%.3f mm electrode is usable (margin %.3f mm): change the electrode "
                  "(edmhmi electrode change) first",
                  h.line, holes.back().cumulative_mm, h.cumulative_mm, usable > 0 ? usable : 0.0,
                  length, margin);
    return error(ErrorCode::kInvalidState, text,
                 Json{{"line", h.line}, {"needed_mm", h.cumulative_mm}, {"usable_mm", usable}});
  }
  return std::nullopt;
}

constexpr char kAxisNames[3] = {'X', 'Y', 'Z'};

int axis_index(const std::string& a) {
  if (a == "X" || a == "x") return 0;
  if (a == "Y" || a == "y") return 1;
  if (a == "Z" || a == "z") return 2;
  return -1;
}

/// Manual motion needs a machine that has it. When it may run (READY, no job, no other manual
/// operation) is the op table's (op_table.cpp), checked before any op runs.
std::optional<Body> manual_available(rt::Runtime& rt) {
  if (!rt.manual().info().available) {
    return error(ErrorCode::kInvalidState, "this machine has no manual motion (no EdmJob)");
  }
  return std::nullopt;
}

/// Queues `r` for the RT side; the reply body with its seq, or busy when the queue is full.
Body send_manual(rt::Runtime& rt, const rt::ManualRequest& r, Json body = Json::object()) {
  const std::uint64_t seq = rt.manual().request(r);
  if (seq == 0) {
    return error(ErrorCode::kBusy, "the runtime has not taken the last " +
                                       std::to_string(rt::ManualControl::kQueueCapacity) +
                                       " manual requests; nothing was queued");
  }
  body["seq"] = seq;
  return body;
}

}  // namespace

Body op_home(Session& s, const Json& msg) {
  auto& rt = s.server().rt;
  if (auto e = manual_available(rt)) return *e;
  if (!rt.manual().info().home) {
    return error(ErrorCode::kInvalidState, "this machine has no reference switches wired");
  }
  std::uint8_t mask = 0x7;
  if (auto it = msg.find("axes"); it != msg.end()) {
    if (!it->is_string() || it->get_ref<const std::string&>().empty() ||
        it->get_ref<const std::string&>().size() > 3) {
      return error(ErrorCode::kBadRequest, "'axes' must be a string of X, Y, Z (e.g. \"XY\")");
    }
    mask = 0;
    for (char c : it->get_ref<const std::string&>()) {
      const int a = axis_index(std::string(1, c));
      if (a < 0 || (mask >> a & 1U) != 0) {
        return error(ErrorCode::kBadRequest, "'axes' must be a string of X, Y, Z (e.g. \"XY\")");
      }
      mask = static_cast<std::uint8_t>(mask | (1U << a));
    }
  }
  rt::ManualRequest r;
  r.op = rt::ManualOp::kHome;
  r.axes = mask;
  std::string axes;
  for (int a = 0; a < 3; ++a) {
    if ((mask >> a & 1U) != 0) axes += kAxisNames[a];
  }
  return send_manual(rt, r, Json{{"axes", axes}});
}

Body op_jog(Session& s, const Json& msg) {
  auto& rt = s.server().rt;
  if (auto e = manual_available(rt)) return *e;
  const Json* axis = field(msg, "axis", [](const Json& j) { return j.is_string(); });
  const int a = axis != nullptr ? axis_index(axis->get<std::string>()) : -1;
  if (a < 0) return error(ErrorCode::kBadRequest, "'axis' must be \"X\", \"Y\" or \"Z\"");
  const Json* dist = field(msg, "distance", [](const Json& j) { return j.is_number(); });
  const Json* vel = field(msg, "velocity", [](const Json& j) { return j.is_number(); });
  if ((dist == nullptr) == (vel == nullptr)) {
    return error(ErrorCode::kBadRequest,
                 "give either 'distance' (mm, incremental) or 'velocity' (mm/s, continuous)");
  }
  const rt::ManualInfo info = rt.manual().info();
  rt::ManualRequest r;
  r.axis = static_cast<std::uint8_t>(a);
  if (dist != nullptr) {
    const double d = dist->get<double>();
    if (!std::isfinite(d) || std::abs(d) < info.jog_distance_min_mm ||
        std::abs(d) > info.jog_distance_max_mm) {
      return error(ErrorCode::kBadRequest, "'distance' must be 0.001 to 10 mm in magnitude");
    }
    r.op = rt::ManualOp::kJogDistance;
    r.value = d;
  } else {
    const double v = vel->get<double>();
    if (!std::isfinite(v) || std::abs(v) > info.jog_v_max_mm_s) {
      return error(ErrorCode::kBadRequest,
                   "'velocity' must be within ±" + std::to_string(info.jog_v_max_mm_s) + " mm/s");
    }
    r.op = rt::ManualOp::kJogVelocity;
    r.value = v;
  }
  return send_manual(rt, r, Json{{"deadman_ms", info.deadman_ms}});
}

Body op_jog_stop(Session& s, const Json& /*msg*/) {
  rt::ManualRequest r;
  r.op = rt::ManualOp::kStop;
  return send_manual(s.server().rt, r);
}

Body op_touch(Session& s, const Json& msg) {
  auto& rt = s.server().rt;
  if (auto e = manual_available(rt)) return *e;
  if (!rt.manual().info().touch) {
    return error(ErrorCode::kInvalidState, "this machine has no contact sensing wired");
  }
  const Json* t = field(msg, "target", [](const Json& j) { return j.is_string(); });
  rt::TouchTarget target{};
  if (t == nullptr || !rt::touch_target_from_string(t->get_ref<const std::string&>(), target)) {
    return error(ErrorCode::kBadRequest,
                 "'target' must be one of \"z\", \"x+\", \"x-\", \"y+\", \"y-\", \"center\"");
  }
  rt::ManualRequest r;
  r.op = rt::ManualOp::kTouch;
  r.target = target;
  return send_manual(rt, r);
}

namespace {

Json referenced_json(std::uint8_t mask) {
  return Json{{"X", (mask & 1U) != 0}, {"Y", (mask & 2U) != 0}, {"Z", (mask & 4U) != 0}};
}

}  // namespace

Body op_manual_status(Session& s, const Json& /*msg*/) {
  auto& m = s.server().rt.manual();
  const rt::ManualStatus st = m.status();
  Json out{{"mode", std::string(rt::to_string(st.mode))},
           {"busy", st.busy},
           {"seen_seq", st.seen_seq},
           {"refused_seq", st.refused_seq},
           {"referenced", referenced_json(m.referenced())},
           {"may_run_programs", m.may_run_programs()}};
  const rt::ManualResult& r = st.result;
  if (r.seq != 0) {
    Json res{{"seq", r.seq},
             {"op", std::string(rt::to_string(r.op))},
             {"ok", r.ok},
             {"error", std::string(rt::to_string(r.error))},
             {"code", std::string(rt::error_code(r.error))},
             {"x", r.x},
             {"y", r.y},
             {"z", r.z},
             {"t_s", r.t_s}};
    if (r.op == rt::ManualOp::kTouch) {
      res["target"] = std::string(rt::to_string(r.target));
      if (r.target == rt::TouchTarget::kCenter) res["size"] = r.size;
    }
    out["result"] = std::move(res);
  }
  return out;
}

Json manual_info_json(const rt::ManualInfo& info) {
  return Json{
      {"available", info.available},
      {"home", info.home},
      {"touch", info.touch},
      {"reference_required", info.reference_required},
      {"deadman_ms", info.deadman_ms},
      {"jog_v_max_mm_s", info.jog_v_max_mm_s},
      {"jog_distance_mm", Json::array({info.jog_distance_min_mm, info.jog_distance_max_mm})},
      {"electrode_d_mm", info.electrode_d_mm}};
}

std::optional<Body> read_upload_options(const Json& msg, rt::JobSlot& slot,
                                        std::optional<std::uint64_t>& offsets_generation) {
  slot = rt::JobSlot::kMain;
  if (auto it = msg.find("slot"); it != msg.end()) {
    if (*it == "mdi") {
      slot = rt::JobSlot::kMdi;
    } else if (*it != "main") {
      return error(ErrorCode::kBadRequest, "'slot' must be \"main\" or \"mdi\"");
    }
  }
  offsets_generation.reset();
  if (auto it = msg.find("offsets_generation"); it != msg.end()) {
    if (!it->is_number_unsigned()) {
      return error(ErrorCode::kBadRequest, "'offsets_generation' must be an unsigned integer");
    }
    offsets_generation = it->get<std::uint64_t>();
  }
  return std::nullopt;
}

std::optional<Body> prepare_start(Session& s, const Json& msg) {
  auto& srv = s.server();
  auto& rt = srv.rt;
  rt::StartOptions o;
  if (auto it = msg.find("slot"); it != msg.end()) {
    if (*it == "mdi") {
      o.slot = rt::JobSlot::kMdi;
    } else if (*it != "main") {
      return error(ErrorCode::kBadRequest, "'slot' must be \"main\" or \"mdi\"");
    }
  }
  if (auto it = msg.find("dry_run"); it != msg.end()) {
    if (!it->is_boolean()) return error(ErrorCode::kBadRequest, "'dry_run' must be true or false");
    o.dry_run = it->get<bool>();
  }
  const rt::JobStore& job = rt.job();
  if (job.has_runner()) {
    if (o.slot == rt::JobSlot::kMdi && job.loaded_mdi_blocks() == 0) {
      return error(ErrorCode::kInvalidState,
                   "cycle.start: no MDI program (program.begin with \"slot\": \"mdi\")");
    }
    if (o.slot == rt::JobSlot::kMain && job.loaded_blocks() == 0) {
      return error(ErrorCode::kInvalidState,
                   "cycle.start: no part program loaded (program.commit)");
    }
    const rt::ManualControl& m = rt.manual();
    if (!m.may_run_programs()) {
      return error(ErrorCode::kInvalidState,
                   "machine not referenced: home every axis first (edmhmi home)");
    }
    const auto& gen = srv.committed_offsets[static_cast<std::size_t>(o.slot)];
    if (gen && *gen != rt.work_offsets().generation()) {
      return error(ErrorCode::kInvalidState,
                   "the work offsets changed since the program was committed (generation " +
                       std::to_string(*gen) + ", now " +
                       std::to_string(rt.work_offsets().generation()) +
                       "): interpret and commit it again");
    }
    // A program that drills waits for the measurement; moves (to the tool setter) do not.
    if (const ElectrodeEntry* e = srv.electrodes->current();
        !o.dry_run && e != nullptr && e->unmeasured &&
        !srv.committed_wear[static_cast<std::size_t>(o.slot)].empty()) {
      return error(ErrorCode::kInvalidState,
                   "the electrode " + e->id +
                       " was put in the spindle and not measured: measure it first (edmhmi "
                       "electrode measure setter)");
    }
    if (!o.dry_run) {
      if (auto refused =
              electrode_too_short(rt, srv.committed_wear[static_cast<std::size_t>(o.slot)])) {
        return refused;
      }
    }
  }
  rt.job().set_start_options(o);
  return std::nullopt;
}

}  // namespace edm::bridge::ops
