#include "retain_offsets.hpp"

#include <cmath>
#include <string>

namespace edm::rt::retain_offsets {
namespace {

constexpr const char* kElectrode = "electrode.length_mm";

// The retained fields of a frame, in the file's order.
struct Field {
  const char* name;
  double WorkFrame::*member;
};
constexpr Field kFields[] = {{"x", &WorkFrame::x},
                             {"y", &WorkFrame::y},
                             {"z", &WorkFrame::z},
                             {"z_electrode_mm", &WorkFrame::z_electrode_mm}};

std::string name(int frame, const Field& f) {
  return "offsets." + WorkOffsets::frame_name(frame) + "." + f.name;
}

}  // namespace

std::vector<RetainStore::Variable> variables(const WorkOffsets& offsets,
                                             const Electrode& electrode) {
  std::vector<RetainStore::Variable> out;
  for (int frame = 0; frame < WorkOffsets::kFrames; ++frame) {
    for (const Field& f : kFields) {
      out.push_back({name(frame, f), RetainType::kReal,
                     [&offsets, frame, member = f.member] {
                       return RetainValue::make_real(offsets.get(frame).*member);
                     },
                     /*urgent=*/true});
    }
  }
  // Not urgent: it changes every cycle while a job drills; the periodic sync and the job's end
  // keep it (a crash loses at most the wear of the last sync interval).
  out.push_back({kElectrode, RetainType::kReal,
                 [&electrode] { return RetainValue::make_real(electrode.length_mm()); },
                 /*urgent=*/false});
  return out;
}

int take(RetainMap& values, WorkOffsets& offsets, Electrode& electrode) {
  int set = 0;
  auto take_real = [&](const std::string& key, double& into) {
    auto it = values.find(key);
    if (it == values.end()) return;
    if (it->second.type == RetainType::kReal && std::isfinite(it->second.r)) {
      into = it->second.r;
      ++set;
    }
    values.erase(it);
  };
  for (int frame = 0; frame < WorkOffsets::kFrames; ++frame) {
    WorkFrame f = offsets.get(frame);
    const int before = set;
    for (const Field& field : kFields) take_real(name(frame, field), f.*field.member);
    if (set > before) offsets.restore(frame, f);
  }
  double length = electrode.length_mm();
  take_real(kElectrode, length);
  electrode.set_length_mm(length);
  return set;
}

}  // namespace edm::rt::retain_offsets
