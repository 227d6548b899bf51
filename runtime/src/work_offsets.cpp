#include "edm/runtime/work_offsets.hpp"

#include <cmath>

namespace edm::rt {

std::optional<int> WorkOffsets::frame_index(std::string_view name) noexcept {
  if (name.size() != 3 || (name[0] != 'G' && name[0] != 'g') || name[1] != '5') return std::nullopt;
  if (name[2] < '4' || name[2] > '9') return std::nullopt;
  return name[2] - '4';
}

std::string WorkOffsets::frame_name(int index) { return "G5" + std::to_string(4 + index); }

WorkFrame WorkOffsets::get(int index) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return index >= 0 && index < kFrames ? frames_[static_cast<std::size_t>(index)] : WorkFrame{};
}

std::array<WorkFrame, WorkOffsets::kFrames> WorkOffsets::all() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

WorkFrame WorkOffsets::set(int index, std::optional<double> x, std::optional<double> y,
                           std::optional<double> z, double z_electrode_mm) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (index < 0 || index >= kFrames) return {};
  WorkFrame& f = frames_[static_cast<std::size_t>(index)];
  if (x && std::isfinite(*x)) f.x = *x;
  if (y && std::isfinite(*y)) f.y = *y;
  if (z && std::isfinite(*z)) {
    f.z = *z;
    f.z_electrode_mm = std::isfinite(z_electrode_mm) && z_electrode_mm > 0.0 ? z_electrode_mm : 0.0;
  }
  ++generation_;
  return f;
}

void WorkOffsets::restore(int index, const WorkFrame& frame) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (index < 0 || index >= kFrames) return;
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  frames_[static_cast<std::size_t>(index)] = {
      finite(frame.x), finite(frame.y), finite(frame.z),
      frame.z_electrode_mm > 0.0 ? finite(frame.z_electrode_mm) : 0.0};
  ++generation_;
}

std::uint64_t WorkOffsets::generation() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return generation_;
}

}  // namespace edm::rt
