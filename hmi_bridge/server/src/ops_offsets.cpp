// The ops of the work offsets (ops_handlers.hpp; docs/protocol.md "Work offsets and the
// electrode"):
//   offset.get, offset.set        → rt::WorkOffsets G54…G59, each Z with the electrode length it
//                                   was set with
// (the electrode's ops: ops_electrode.cpp)
// A change is on disk before the reply, or undone and refused (retain_failed, alarm 183).
#include <spdlog/spdlog.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {
namespace {

Json frame_json(const rt::WorkFrame& f) {
  return Json{{"x", f.x}, {"y", f.y}, {"z", f.z}, {"z_electrode_mm", f.z_electrode_mm}};
}

}  // namespace

std::optional<Body> retained_or_undone(Session& s, const std::string& what,
                                       const std::function<void()>& undo) {
  rt::Runtime& rt = s.server().rt;
  if (rt.retain() == nullptr || rt.retain()->sync() != rt::RetainStore::SyncResult::kFailed) {
    return std::nullopt;
  }
  // The operator must never believe a value is kept that the next start will not have.
  undo();
  s.log(spdlog::level::warn, "{} not set: the retain file could not be written", what);
  return error(ErrorCode::kRetainFailed,
               what + " could not be retained (alarm 183: the retain file '" + rt.retain()->path() +
                   "' could not be written); " + what + " is unchanged");
}

Body op_offset_get(Session& s, const Json& /*msg*/) {
  rt::Runtime& rt = s.server().rt;
  auto& w = rt.work_offsets();
  Json frames = Json::object();
  const auto all = w.all();
  for (int i = 0; i < rt::WorkOffsets::kFrames; ++i) {
    frames[rt::WorkOffsets::frame_name(i)] = frame_json(all[static_cast<std::size_t>(i)]);
  }
  return Json{{"frames", std::move(frames)},
              {"generation", w.generation()},
              {"electrode_mm", rt.electrode().length_mm()}};
}

Body op_offset_set(Session& s, const Json& msg) {
  auto& rt = s.server().rt;
  const Json* f = field(msg, "frame", [](const Json& j) { return j.is_string(); });
  const auto index =
      f != nullptr ? rt::WorkOffsets::frame_index(f->get_ref<const std::string&>()) : std::nullopt;
  if (!index) return error(ErrorCode::kBadRequest, "'frame' must be one of G54 … G59");
  std::optional<double> v[3];
  const char* keys[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    auto it = msg.find(keys[k]);
    if (it == msg.end()) continue;
    if (!it->is_number() || !std::isfinite(it->get<double>()) ||
        std::abs(it->get<double>()) > 1e5) {
      return error(ErrorCode::kBadRequest,
                   std::string("'") + keys[k] + "' must be a finite number of mm (|v| ≤ 1e5)");
    }
    v[k] = it->get<double>();
    // The work origin is a point of the machine: inside the axis's soft limits (issue 33: G55 Y
    // 5000 was accepted on a ±100 mm machine, and every program in that frame then refused).
    const char axis = static_cast<char>('X' + k);
    if (const machining::AxisLimits* lim = rt.tables().axis(axis);
        lim != nullptr && (*v[k] < lim->min_mm || *v[k] > lim->max_mm)) {
      return error(ErrorCode::kBadRequest,
                   fmt::format("'{}' {} mm is outside the {} soft limits ({} .. {} mm): the work "
                               "origin must be a point the machine reaches",
                               keys[k], *v[k], axis, lim->min_mm, lim->max_mm));
    }
  }
  if (!v[0] && !v[1] && !v[2]) {
    return error(ErrorCode::kBadRequest, "give at least one of 'x', 'y', 'z'");
  }
  const std::string name = rt::WorkOffsets::frame_name(*index);
  const rt::WorkFrame before = rt.work_offsets().get(*index);
  // A new Z remembers the electrode length it was set with: the job compensates what is lost.
  const rt::WorkFrame nf =
      rt.work_offsets().set(*index, v[0], v[1], v[2], rt.electrode().length_mm());
  if (auto refused =
          retained_or_undone(s, name, [&] { rt.work_offsets().restore(*index, before); })) {
    return *refused;
  }
  s.log(spdlog::level::info, "set {} to X{} Y{} Z{} (electrode {} mm)", name, nf.x, nf.y, nf.z,
        nf.z_electrode_mm);
  Json out = frame_json(nf);
  out["frame"] = name;
  out["generation"] = rt.work_offsets().generation();
  out["retained"] = rt.retain() != nullptr;  // false: this run retains nothing (no retain file)
  return out;
}

}  // namespace edm::bridge::ops
