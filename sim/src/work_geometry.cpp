#include "edm/sim/work_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace edm::sim {
namespace {

double tool_half_x(const Section& t) noexcept { return t.half_x_mm; }
double tool_half_y(const Section& t) noexcept { return t.disc ? t.half_x_mm : t.half_y_mm; }

bool contains(const Section& s, double x, double y) noexcept {
  const double dx = x - s.x_mm, dy = y - s.y_mm;
  if (s.disc) return std::hypot(dx, dy) < s.half_x_mm;
  return std::abs(dx) < s.half_x_mm && std::abs(dy) < s.half_y_mm;
}

// The tool's centre is outside the (rectangular) block: distance to its outline.
double outside_distance(const Section& tool, const Section& block) noexcept {
  const double ex = std::abs(tool.x_mm - block.x_mm) - block.half_x_mm;
  const double ey = std::abs(tool.y_mm - block.y_mm) - block.half_y_mm;
  if (tool.disc) {
    return std::max(0.0, std::hypot(std::max(0.0, ex), std::max(0.0, ey)) - tool.half_x_mm);
  }
  return std::hypot(std::max(0.0, ex - tool.half_x_mm), std::max(0.0, ey - tool.half_y_mm));
}

// The tool's centre is inside the hole: clearance to its wall.
double inside_clearance(const Section& tool, const Section& hole) noexcept {
  const double dx = std::abs(tool.x_mm - hole.x_mm), dy = std::abs(tool.y_mm - hole.y_mm);
  double c = 0.0;
  if (hole.disc) {
    // The farthest point of a disc is on the line through the centres; of a rectangle, a corner.
    c = tool.disc ? hole.half_x_mm - std::hypot(dx, dy) - tool.half_x_mm
                  : hole.half_x_mm - std::hypot(dx + tool.half_x_mm, dy + tool.half_y_mm);
  } else {
    c = std::min(hole.half_x_mm - dx - tool_half_x(tool), hole.half_y_mm - dy - tool_half_y(tool));
  }
  return std::max(0.0, c);
}

}  // namespace

double plan_distance_mm(const Section& tool, const Section& block, const Section* holes,
                        std::size_t n_holes) noexcept {
  const bool outside = std::abs(tool.x_mm - block.x_mm) > block.half_x_mm ||
                       std::abs(tool.y_mm - block.y_mm) > block.half_y_mm;
  if (outside) return outside_distance(tool, block);
  double best = -1.0;
  for (std::size_t i = 0; i < n_holes; ++i) {
    const Section& h = holes[i];
    if (!h.none() && contains(h, tool.x_mm, tool.y_mm)) {
      best = std::max(best, inside_clearance(tool, h));
    }
  }
  return best < 0.0 ? 0.0 : best;
}

double distance_to_work_mm(const Section& tool, double tip_z_mm, bool through,
                           const WorkSolid& work) noexcept {
  auto prism = [&](double top_z_mm, const Section* holes, std::size_t n) {
    const double dz = through ? 0.0 : std::max(0.0, tip_z_mm - top_z_mm);
    return std::hypot(plan_distance_mm(tool, work.block, holes, n), dz);
  };
  const std::array<Section, 2> top_holes{work.bore, work.hole};
  double d = prism(0.0, top_holes.data(), top_holes.size());
  if (!work.hole.none() && work.hole_depth_mm > 0.0) {
    d = std::min(d, prism(-work.hole_depth_mm, &work.bore, 1));
  }
  return d;
}

}  // namespace edm::sim
