#pragma once
// The distance between the electrode and the work's material, for touch sensing
// (docs/simulator.md §3a). Both are prisms over horizontal cross-sections: the electrode a disc
// or a rectangle from its tip upward, the work a rectangular block from its surface downward less
// a through bore and the hole drilled so far. For prisms A×I and B×J the distance is
// √(d_xy(A, B)² + d_z(I, J)²), so the 3-D problem splits into a plan view and a height.
//
// RT-safety: pure arithmetic, noexcept, no allocation. Thread-safety: pure functions.

#include <cstddef>

namespace edm::sim {

/// A horizontal cross-section centred at (x_mm, y_mm): a disc of radius half_x_mm, or an
/// axis-aligned rectangle of half sizes half_x_mm × half_y_mm. A disc or rectangle of size 0 is
/// "none" where a hole is expected.
struct Section {
  double x_mm{0.0}, y_mm{0.0};
  double half_x_mm{0.0}, half_y_mm{0.0};
  bool disc{true};

  [[nodiscard]] bool none() const noexcept { return half_x_mm <= 0.0; }
};

/// Plan-view distance (mm, ≥ 0) from the electrode section `tool` to `block` less `holes`
/// (holes open through the top of the prism). 0 when they overlap. Where the tool's centre is
/// outside the block, the distance to the block's outline (holes at its edge are ignored);
/// inside a hole, the clearance to that hole's wall (the largest, if the centre is in two);
/// over material, 0. Holes are expected inside the block.
[[nodiscard]] double plan_distance_mm(const Section& tool, const Section& block,
                                      const Section* holes, std::size_t n_holes) noexcept;

/// The work as the touch sensing sees it, in the plant's frame (surface at z = 0).
struct WorkSolid {
  Section block;  // rectangle
  Section bore;   // disc; none() = no bore (through)
  Section hole;   // the drilled hole (disc or rectangle); none() = no hole
  double hole_depth_mm{0.0};
};

/// Distance (mm, ≥ 0) from an electrode of section `tool` whose tip is at tip_z_mm (plant frame)
/// to the material of `work`: the top prism (block less bore and hole, below z = 0) and, when
/// there is a hole, the prism under its bottom (block less bore, below −hole_depth_mm).
/// `through`: the electrode spans every height (a wire), so only the plan view counts.
[[nodiscard]] double distance_to_work_mm(const Section& tool, double tip_z_mm, bool through,
                                         const WorkSolid& work) noexcept;

}  // namespace edm::sim
