#pragma once
// The work of a wire machine in plan view (docs/simulator.md §7b): a plate whose material is a
// signed-distance field on a square grid, eroded where the wire's discharges remove it, so the
// front gap of a main cut, the side gap of a skim, the kerf and the wall left behind all follow
// from the path the axes took.
//
// The field φ is > 0 in the material and < 0 in the void (the start hole, the kerf, outside the
// plate); |φ| is the distance to the boundary near it (exact at the boundary, a lower bound deep
// inside). Erosion is a union of discs: a discharge burst at the wire's centre p removes the
// material within R of p, φ ← min(φ, |c − p| − R), with R grown from the clearance by the burst's
// volume over the thickness and the engaged arc of the wire (the part of a circle round p that
// meets material). The thickness varies in plan: a plate, a step along a line x = const, and an
// internal round void in the middle of the thickness.
//
// RT-safety: construction allocates the grid (non-RT); every other member is noexcept and
// allocation-free. Thread-safety: one thread.

#include <array>
#include <cstddef>
#include <vector>

namespace edm::sim {

struct WirePlaneGeometry {
  double x_min_mm{-15.0}, x_max_mm{15.0};  // the plate, machine XY
  double y_min_mm{-15.0}, y_max_mm{15.0};
  double thickness_mm{20.0};
  double cell_mm{0.01};                        // grid pitch
  double hole_x_mm{0.0}, hole_y_mm{0.0};       // the start hole's centre ...
  double hole_d_mm{0.0};                       // ... and diameter (0: none)
  double step_x_mm{0.0}, step_mm{0.0};         // x >= step_x: thickness + step (0: none)
  double void_x_mm{0.0}, void_y_mm{0.0};       // an internal void's centre ...
  double void_d_mm{0.0}, void_height_mm{0.0};  // ... diameter and height (0: none)
};

class WirePlane {
 public:
  WirePlane() = default;  // none: active() is false
  /// Allocates the grid over the plate and a margin. Non-RT.
  explicit WirePlane(const WirePlaneGeometry& g);

  [[nodiscard]] bool active() const noexcept { return nx_ > 0; }
  [[nodiscard]] const WirePlaneGeometry& geometry() const noexcept { return g_; }

  /// The distance from (x, y) to the nearest material (mm): ≥ 0 in the void, < 0 in the material.
  /// The field's zero level is searched along kRays rays (the field near a disc's centre is a
  /// cone's apex, which interpolation blurs by ~h; its boundary is accurate to ~h²/8R); the
  /// nearest boundary point is cached until the field changes or (x, y) moves kReuseMm, so the
  /// pulses between two erosions cost one distance each. RT-safe.
  [[nodiscard]] double clearance_mm(double x, double y) const noexcept;
  /// The thickness of material the wire cuts at (x, y): the plate, the step, less a void.
  [[nodiscard]] double cut_thickness_mm(double x, double y) const noexcept;
  /// Removes `volume_mm3` where a wire centred at (x, y) meets the material within `reach_mm` of
  /// its centre. Returns the volume it could not place (no material within reach). RT-safe.
  double erode(double x, double y, double reach_mm, double volume_mm3) noexcept;
  /// The truth, for measuring a part: from (x, y) in the material, the distance along the unit
  /// vector (ux, uy) to the first void, interpolated to the boundary; −1 when there is none
  /// within max_mm or (x, y) is not in the material. RT-safe (but O(max_mm / cell)).
  [[nodiscard]] double edge_along_mm(double x, double y, double ux, double uy,
                                     double max_mm) const noexcept;
  /// The material removed so far (mm³, of the field's cells × thickness): a check of the
  /// erosion's bookkeeping. O(cells), non-RT use.
  [[nodiscard]] double removed_mm3() const noexcept;

 private:
  [[nodiscard]] double phi(double x, double y) const noexcept;  // bilinear
  [[nodiscard]] double cell_phi(long i, long j) const noexcept;
  /// The nearest boundary point from (x, y) in the void, by the rays and then by halving the
  /// angle about the best one; false if none within 2 mm.
  bool search(double x, double y, double& qx, double& qy) const noexcept;
  /// Where the ray from (x, y) along (ux, uy) first meets material, marching from `lo` up to
  /// `limit` (mm); kFar when it does not.
  [[nodiscard]] double crossing(double x, double y, double ux, double uy, double lo,
                                double limit) const noexcept;

  static constexpr int kDirections = 48;  // rays of the clearance, samples of the engaged arc
  std::array<double, kDirections> cos_{}, sin_{};
  WirePlaneGeometry g_{};
  long nx_{0}, ny_{0};
  double x0_{0.0}, y0_{0.0}, h_{0.0};
  std::vector<float> phi_;
  std::vector<float> phi0_;  // the field at the start (removed_mm3)
  struct ShellCell {
    double rho, m;  // distance from the erosion's centre, the cell's φ
  };
  std::vector<ShellCell> shell_;  // erode()'s cells near the boundary (allocated once)
  // The cache of clearance_mm(): where it searched, the boundary point it found.
  mutable bool cached_{false};
  mutable bool cached_none_{false};
  mutable bool stale_{false};  // the field changed since
  mutable double cx_{0.0}, cy_{0.0}, qx_{0.0}, qy_{0.0};
};

}  // namespace edm::sim
