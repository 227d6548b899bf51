// The electrode's ops (ops_handlers.hpp; docs/protocol.md "Work offsets and the electrode"):
//   electrode.get      the length the job compensates with (rt::Electrode), the table, the setter
//   electrode.set      a length measured off the machine (a presetter, a caliper)
//   electrode.change   the electrode in the spindle is another one (ElectrodeTable)
//   electrode.measure  its length by touching the tool setter or the work (a manual Z touch
//                      whose contact the progress tick turns into the length: watch_measure)
// A change is on disk before the reply, or undone and refused (retain_failed, alarm 183).
#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>
#include <string>

#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge {
namespace {

/// How far from the tool setter's XY a measurement on it may touch [mm].
constexpr double kSetterToleranceMm = 0.05;

Json entry_json(const ElectrodeEntry& e) {
  const auto ratio = [](std::optional<double> r) { return r ? Json(*r) : Json(nullptr); };
  Json j = to_json(e);
  j["measured"] = !e.unmeasured;
  j["wear_ratio"] = ratio(e.measured_wear_ratio());
  j["wear_ratio_estimated"] = ratio(e.estimated_wear_ratio());
  return j;
}

std::string wall_now() { return ops::wall_time(std::chrono::system_clock::now()); }

Json electrode_json(Server::Impl& srv) {
  rt::Runtime& rt = srv.rt;
  const double l = rt.electrode().length_mm();
  const double margin = rt.config().machine.safety.electrode_margin_mm;
  Json table = Json::array();
  for (const ElectrodeEntry& e : srv.electrodes->entries()) {
    Json j = entry_json(e);
    if (&e == srv.electrodes->current()) j["length_mm"] = l;  // the runtime's, live
    table.push_back(std::move(j));
  }
  const ElectrodeEntry* cur = srv.electrodes->current();
  Json setter = nullptr;
  if (const auto& ts = rt.config().machine.electrode.tool_setter) {
    setter = Json{{"x_mm", ts->x_mm}, {"y_mm", ts->y_mm}, {"z_mm", ts->z_mm}};
  }
  return Json{{"length_mm", l},
              {"known", l > 0.0},
              {"margin_mm", margin},
              {"usable_mm", l > margin ? l - margin : 0.0},
              {"retained", rt.retain() != nullptr},
              {"current", cur != nullptr ? Json(cur->id) : Json(nullptr)},
              {"table", std::move(table)},
              {"table_retained", srv.electrodes->retained()},
              {"tool_setter", std::move(setter)},
              {"measuring", srv.measuring ? Json(srv.measuring->seq) : Json(nullptr)},
              {"last_measure", srv.last_measure}};
}

}  // namespace

void Server::Impl::watch_measure() {
  if (!measuring) return;
  const rt::ManualStatus st = rt.manual().status();
  const PendingMeasure m = *measuring;
  Json out{{"seq", m.seq}, {"reference", m.reference}, {"ok", false}, {"t", wall_now()}};
  if (st.refused_seq == m.seq) {
    out["error"] = "another manual operation was running: nothing was measured";
  } else if (st.result.seq != m.seq || st.busy) {
    return;  // not ended yet
  } else if (!st.result.ok) {
    out["error"] = std::string("the touch failed: ") + std::string(rt::to_string(st.result.error));
  } else {
    const auto& ts = rt.config().machine.electrode.tool_setter;
    const double length = st.result.z - m.datum_mm;
    if (m.reference == "setter" && ts &&
        std::hypot(st.result.x - ts->x_mm, st.result.y - ts->y_mm) > kSetterToleranceMm) {
      out["error"] = fmt::format(
          "touched at X{:.3f} Y{:.3f}, not on the tool setter at X{:.3f} Y{:.3f}: move there "
          "first (edmhmi electrode measure setter does)",
          st.result.x, st.result.y, ts->x_mm, ts->y_mm);
    } else if (!(length > 0.0 && length <= 1e4)) {
      out["error"] = fmt::format(
          "the contact at Z{:.4f} gives a length of {:.4f} mm, not in (0, 10000]: check the "
          "tool setter's z_mm or the frame's Z",
          st.result.z, length);
    } else {
      const double before = rt.electrode().length_mm();
      rt.electrode().set_length_mm(length);
      if (rt.retain() != nullptr && rt.retain()->sync() == rt::RetainStore::SyncResult::kFailed) {
        rt.electrode().set_length_mm(before);
        out["error"] = "the length could not be retained (alarm 183): it is unchanged";
      } else {
        electrodes->measured(length);
        electrodes->save();
        out["ok"] = true;
        out["length_mm"] = length;
        out["was_mm"] = before;
        out["contact_z_mm"] = st.result.z;
        spdlog::info("bridge: electrode measured on the {}: {:.4f} mm (the estimate was {:.4f})",
                     m.reference, length, before);
      }
    }
  }
  if (!out.value("ok", false)) {
    spdlog::warn("bridge: electrode measurement failed: {}", out.value("error", ""));
  }
  last_measure = std::move(out);
  measuring.reset();
}

namespace ops {

Body op_electrode_get(Session& s, const Json& /*msg*/) { return electrode_json(s.server()); }

Body op_electrode_set(Session& s, const Json& msg) {
  Server::Impl& srv = s.server();
  rt::Runtime& rt = srv.rt;
  const Json* l = field(msg, "length_mm", [](const Json& j) {
    return j.is_number() && std::isfinite(j.get<double>()) && j.get<double>() > 0.0 &&
           j.get<double>() <= 1e4;
  });
  if (l == nullptr) {
    return error(ErrorCode::kBadRequest,
                 "'length_mm' must be the electrode's length, a number of mm in (0, 10000]");
  }
  const double before = rt.electrode().length_mm();
  rt.electrode().set_length_mm(l->get<double>());
  if (auto refused = retained_or_undone(s, "the electrode length",
                                        [&] { rt.electrode().set_length_mm(before); })) {
    return *refused;
  }
  // A length measured off the machine is a measurement like one on the setter.
  srv.electrodes->measured(l->get<double>());
  srv.electrodes->save();
  s.log(spdlog::level::info, "electrode length set to {} mm (was {} mm)", l->get<double>(), before);
  return electrode_json(srv);
}

Body op_electrode_change(Session& s, const Json& msg) {
  Server::Impl& srv = s.server();
  rt::Runtime& rt = srv.rt;
  const Json* id = field(msg, "electrode", [](const Json& j) { return j.is_string(); });
  const std::string why_id = id != nullptr ? ElectrodeTable::invalid_id(id->get<std::string>())
                                           : "'electrode' (its id) is required";
  if (!why_id.empty()) return error(ErrorCode::kBadRequest, why_id);
  const ElectrodeEntry* known = srv.electrodes->find(id->get<std::string>());
  ElectrodeEntry e = known != nullptr ? *known : ElectrodeEntry{};
  e.id = id->get<std::string>();
  // A new electrode needs all of its fields; a known one may take any of them anew.
  for (const char* key : {"kind", "material"}) {
    auto it = msg.find(key);
    if (it == msg.end()) {
      if (known == nullptr) {
        return error(ErrorCode::kBadRequest,
                     std::string("a new electrode needs '") + key +
                         "' (and 'kind', 'size_mm', 'material', 'new_length_mm')");
      }
      continue;
    }
    const std::string v = it->is_string() ? it->get<std::string>() : std::string();
    const std::string why = std::string(key) == "kind" ? ElectrodeTable::invalid_kind(v)
                                                       : ElectrodeTable::invalid_material(v);
    if (!why.empty()) return error(ErrorCode::kBadRequest, why);
    (std::string(key) == "kind" ? e.kind : e.material) = v;
  }
  for (auto [key, dst] :
       {std::pair{"size_mm", &e.size_mm}, std::pair{"new_length_mm", &e.new_length_mm}}) {
    auto it = msg.find(key);
    if (it == msg.end()) {
      if (known == nullptr) {
        return error(ErrorCode::kBadRequest, std::string("a new electrode needs '") + key + "'");
      }
      continue;
    }
    if (!it->is_number() || !std::isfinite(it->get<double>()) || !(it->get<double>() > 0.0) ||
        it->get<double>() > 1e4) {
      return error(ErrorCode::kBadRequest,
                   std::string("'") + key + "' must be a number of mm in (0, 10000]");
    }
    *dst = it->get<double>();
  }
  if (known == nullptr) e.length_mm = e.new_length_mm;
  e.unmeasured = true;
  const double before = rt.electrode().length_mm();
  const ElectrodeTable table_before = *srv.electrodes;
  if (!srv.electrodes->change(e, before, wall_now())) {
    return error(ErrorCode::kInvalidState,
                 fmt::format("the electrode table is full ({} electrodes)", ElectrodeTable::kCap));
  }
  // Until it is measured, the job compensates with what the table says of it.
  rt.electrode().set_length_mm(e.length_mm);
  const auto undo = [&] {
    rt.electrode().set_length_mm(before);
    *srv.electrodes = table_before;
  };
  if (auto refused = retained_or_undone(s, "the electrode change", undo)) return *refused;
  if (!srv.electrodes->save()) {
    undo();
    return error(ErrorCode::kRetainFailed,
                 "the electrode table could not be written: the electrode change is undone");
  }
  s.log(spdlog::level::info,
        "electrode {} ({} {} {} mm) put in the spindle, {} mm; the last "
        "one left at {} mm",
        e.id, e.material, e.kind, e.size_mm, e.length_mm, before);
  return electrode_json(srv);
}

Body op_electrode_measure(Session& s, const Json& msg) {
  Server::Impl& srv = s.server();
  rt::Runtime& rt = srv.rt;
  if (!rt.manual().info().available || !rt.manual().info().touch) {
    return error(ErrorCode::kInvalidState, "this machine has no contact sensing (no touch)");
  }
  if (srv.measuring) {
    return error(ErrorCode::kBusy,
                 "a measurement is running (seq " + std::to_string(srv.measuring->seq) + ")");
  }
  const Json* ref = field(msg, "reference", [](const Json& j) { return j.is_string(); });
  const std::string reference = ref != nullptr ? ref->get<std::string>() : "";
  Server::Impl::PendingMeasure m;
  m.reference = reference;
  if (reference == "setter") {
    const auto& ts = rt.config().machine.electrode.tool_setter;
    if (!ts) {
      return error(ErrorCode::kInvalidState,
                   "this machine has no tool setter (machine.electrode.tool_setter)");
    }
    m.datum_mm = ts->z_mm;
  } else if (reference == "work") {
    std::string frame = "G54";
    if (auto it = msg.find("frame"); it != msg.end()) {
      frame = it->is_string() ? it->get<std::string>() : "";
    }
    const auto index = rt::WorkOffsets::frame_index(frame);
    if (!index) return error(ErrorCode::kBadRequest, "'frame' must be one of G54 … G59");
    const rt::WorkFrame f = rt.work_offsets().get(*index);
    if (!(f.z_electrode_mm > 0.0)) {
      return error(ErrorCode::kInvalidState,
                   frame +
                       "'s Z was not set with a known electrode length: touch the work "
                       "with a measured electrode first, or measure on the tool setter");
    }
    // The work's surface is where the frame's electrode touched it: Z − its length.
    m.datum_mm = f.z - f.z_electrode_mm;
  } else {
    return error(ErrorCode::kBadRequest, "'reference' must be \"setter\" or \"work\"");
  }
  rt::ManualRequest r;
  r.op = rt::ManualOp::kTouch;
  r.target = rt::TouchTarget::kZ;
  m.seq = rt.manual().request(r);
  if (m.seq == 0) return error(ErrorCode::kBusy, "the runtime has not taken the last requests");
  srv.measuring = m;
  s.log(spdlog::level::info, "electrode measurement on the {} (touch seq {})", reference, m.seq);
  return Json{{"seq", m.seq}, {"reference", reference}};
}

}  // namespace ops
}  // namespace edm::bridge
