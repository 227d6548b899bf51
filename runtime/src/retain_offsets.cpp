#include "retain_offsets.hpp"

#include <cmath>
#include <optional>
#include <string>

namespace edm::rt::retain_offsets {
namespace {

std::string name(int frame, char axis) {
  return "offsets." + WorkOffsets::frame_name(frame) + "." + std::string(1, axis);
}

double axis_of(const WorkFrame& f, char axis) {
  return axis == 'x' ? f.x : axis == 'y' ? f.y : f.z;
}

}  // namespace

std::vector<RetainStore::Variable> variables(const WorkOffsets& offsets) {
  std::vector<RetainStore::Variable> out;
  for (int f = 0; f < WorkOffsets::kFrames; ++f) {
    for (char axis : {'x', 'y', 'z'}) {
      out.push_back(
          {name(f, axis), RetainType::kReal,
           [&offsets, f, axis] { return RetainValue::make_real(axis_of(offsets.get(f), axis)); },
           /*urgent=*/true});
    }
  }
  return out;
}

int take(RetainMap& values, WorkOffsets& offsets) {
  int set = 0;
  for (int f = 0; f < WorkOffsets::kFrames; ++f) {
    std::optional<double> v[3];
    int k = 0;
    for (char axis : {'x', 'y', 'z'}) {
      auto it = values.find(name(f, axis));
      if (it != values.end()) {
        if (it->second.type == RetainType::kReal && std::isfinite(it->second.r)) {
          v[k] = it->second.r;
          ++set;
        }
        values.erase(it);
      }
      ++k;
    }
    if (v[0] || v[1] || v[2]) offsets.set(f, v[0], v[1], v[2]);
  }
  return set;
}

}  // namespace edm::rt::retain_offsets
