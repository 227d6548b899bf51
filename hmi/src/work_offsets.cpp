// Work frames: names, conversions and the JSON of offset.get (work_offsets.hpp).
#include "edm/hmi/work_offsets.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>

namespace edm::hmi {

std::string frame_name(int index) {
  if (index < 0 || index >= kWorkFrames) return "G5?";
  return "G5" + std::to_string(4 + index);
}

std::optional<int> frame_index(std::string_view name) {
  if (name.size() != 3 || std::toupper(static_cast<unsigned char>(name[0])) != 'G' ||
      name[1] != '5' || name[2] < '4' || name[2] > '9') {
    return std::nullopt;
  }
  return name[2] - '4';
}

machining::Vec3 to_work(const machining::Vec3& m, const machining::Vec3& o) noexcept {
  return {m.x - o.x, m.y - o.y, m.z - o.z};
}

bool offsets_from_json(const bridge::Json& j, WorkOffsets& out, std::string& error) {
  if (!j.is_object()) {
    error = "expected a JSON object with \"frames\"";
    return false;
  }
  const auto frames = j.find("frames");
  if (frames == j.end() || !frames->is_object()) {
    error = "expected \"frames\": {\"G54\": {\"x\": .., \"y\": .., \"z\": ..}, ...}";
    return false;
  }
  WorkOffsets o;
  for (const auto& [name, f] : frames->items()) {
    const std::optional<int> i = frame_index(name);
    if (!i) {
      error = "unknown work frame \"" + name + "\" (G54..G59)";
      return false;
    }
    if (!f.is_object()) {
      error = name + ": expected {\"x\", \"y\", \"z\"}";
      return false;
    }
    machining::Vec3& v = o.frame[static_cast<std::size_t>(*i)];
    double& length = o.z_electrode_mm[static_cast<std::size_t>(*i)];
    for (auto [key, field] : {std::pair{"x", &v.x}, std::pair{"y", &v.y}, std::pair{"z", &v.z},
                              std::pair{"z_electrode_mm", &length}}) {
      const auto it = f.find(key);
      if (it == f.end()) continue;
      if (!it->is_number() || !std::isfinite(it->get<double>())) {
        error = name + "." + key + ": not a finite number (mm)";
        return false;
      }
      *field = it->get<double>();
    }
    if (length < 0.0) {
      error = name + ".z_electrode_mm: an electrode length cannot be negative";
      return false;
    }
  }
  if (const auto e = j.find("electrode_mm"); e != j.end()) {
    if (!e->is_number() || !std::isfinite(e->get<double>()) || e->get<double>() < 0.0) {
      error = "electrode_mm: not a length (a finite number of mm, >= 0)";
      return false;
    }
    o.electrode_mm = e->get<double>();
  }
  out = o;
  return true;
}

bridge::Json to_json(const WorkOffsets& offsets) {
  bridge::Json frames = bridge::Json::object();
  for (int i = 0; i < kWorkFrames; ++i) {
    const machining::Vec3& v = offsets.frame[static_cast<std::size_t>(i)];
    frames[frame_name(i)] = {
        {"x", v.x},
        {"y", v.y},
        {"z", v.z},
        {"z_electrode_mm", offsets.z_electrode_mm[static_cast<std::size_t>(i)]}};
  }
  return {{"frames", frames}, {"electrode_mm", offsets.electrode_mm}};
}

std::string format_frame(int index, const machining::Vec3& v) {
  char buf[96];
  auto tidy = [](double mm) { return std::fabs(mm) < 5e-5 ? 0.0 : mm; };  // no "-0.0000"
  std::snprintf(buf, sizeof buf, "%s  X %9.4f  Y %9.4f  Z %9.4f", frame_name(index).c_str(),
                tidy(v.x), tidy(v.y), tidy(v.z));
  return buf;
}

}  // namespace edm::hmi
