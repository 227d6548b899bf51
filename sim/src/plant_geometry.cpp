#include "edm/sim/plant.hpp"

// The plant's tool geometry for each tool (tube, block, wire): gaps, gap volume, flushing, the
// wire's cut thickness, where removed material goes, the hole a tube follows. The pulse engine
// (phases, pulses, axes, sensors) is plant.cpp.

#include <algorithm>
#include <cmath>
#include <numbers>

namespace edm::sim {
namespace {

constexpr double kNoGapUm = 1e9;  // no material (or no electrode) in front: never ignites

}  // namespace

double Plant::tool_z_mm(std::int64_t t_ns) const noexcept {
  return axes_[2].position_mm() +
         axes_[2].velocity_mm_s() * static_cast<double>(t_ns - axis_time_ns_) * 1e-9;
}

double Plant::depth_mm() const noexcept { return away_ ? 0.0 : -hole_bottom_mm_; }

double Plant::bottom_mm() const noexcept { return away_ ? 0.0 : hole_bottom_mm_; }

double Plant::front_gap_um(double z_mm) const noexcept {
  if (tool_ != Tool::kWire) {
    if (wear_length_mm_ >= params_.electrode_length_mm) return kNoGapUm;
    if (params_.work_thickness_mm > 0.0 && depth_mm() >= params_.work_thickness_mm) {
      return kNoGapUm;
    }
  }
  if (hold_) return hold_gap_um_;
  if (plane_.active()) {
    return (plane_.clearance_mm(axes_[0].position_mm(), axes_[1].position_mm()) -
            params_.wire_d_mm / 2.0) *
           1e3;
  }
  return (z_mm + wear_length_mm_ - bottom_mm()) * 1e3;
}

double Plant::wall_gap_um(std::size_t j) const noexcept {
  const double off = (axes_[0].position_mm() - hole_cx_mm_) * wall_cos_[j] +
                     (axes_[1].position_mm() - hole_cy_mm_) * wall_sin_[j];
  return (wall_r_mm_[j] - params_.tool_od_mm / 2.0 - off) * 1e3;
}

double Plant::gap_volume_mm3(double gap_um) const noexcept {
  const double g = std::max(gap_um, 1.0) * 1e-3;
  const auto& p = params_;
  switch (tool_) {
    case Tool::kTube:
      return area_front_mm2_ * g + side_area_mm2_ * (state_.wall_radius_mm - p.tool_od_mm / 2.0);
    case Tool::kBlock: return area_front_mm2_ * g + side_area_mm2_ * p.side_gap_mm;
    case Tool::kWire: {
      const double h = cut_thickness_mm();
      return (p.wire_d_mm + 2.0 * g) * h * g + 2.0 * h * p.near_tip_zone_mm * g;
    }
  }
  return area_front_mm2_ * g;
}

double Plant::flush_effective() const noexcept {
  if (!cmd_.flushing_on) return 0.0;
  const auto& p = params_;
  double drop = depth_mm() >= p.flush_drop_depth_mm ? p.flush_drop_factor : 1.0;
  if (tool_ == Tool::kWire && p.wire_hole_to_mm > p.wire_hole_from_mm &&
      depth_mm() + p.wire_nozzle_radius_mm > p.wire_hole_from_mm &&
      depth_mm() - p.wire_nozzle_radius_mm < p.wire_hole_to_mm) {
    drop *= p.wire_hole_flush_factor;  // the flush escapes through the hole under the nozzle
  }
  const double past_wall = depth_mm() - p.wire_cavity_to_mm;
  if (tool_ == Tool::kWire && p.wire_cavity_to_mm > p.wire_cavity_from_mm && past_wall >= 0.0) {
    // The centre part (h_c of H) past a cavity's far wall: its flush escapes into the cavity.
    drop *= 1.0 - cavity_centre_fraction(depth_mm()) * (1.0 - p.wire_cavity_flush_factor) *
                      std::exp(-past_wall / p.wire_cavity_flush_mm);
  }
  return p.flush_factor * std::clamp(cmd_.flushing_strength, 0.0, 1.0) * drop;
}

double Plant::cavity_centre_fraction(double cut_mm) const noexcept {
  return std::min(1.0, params_.wire_cavity_height_mm / profile_.thickness_mm(cut_mm));
}

double Plant::cut_thickness_mm() const noexcept {
  if (plane_.active()) {
    return plane_.cut_thickness_mm(axes_[0].position_mm(), axes_[1].position_mm());
  }
  const double s = depth_mm();
  const auto& p = params_;
  const bool in_cavity = s >= p.wire_cavity_from_mm && s < p.wire_cavity_to_mm;
  return profile_.thickness_mm(s) - (in_cavity ? p.wire_cavity_height_mm : 0.0);
}

void Plant::remove(double volume_mm3, double wear_mm3, double gap_um, int site) noexcept {
  const auto& p = params_;
  state_.removed_mm3 += volume_mm3;
  state_.wear_mm3 += wear_mm3;
  const double v_gap = gap_volume_mm3(gap_um);
  if (tool_ == Tool::kWire) {
    const double h = cut_thickness_mm();
    const double kerf = p.wire_d_mm + 2.0 * std::max(gap_um, 0.0) * 1e-3;  // k = D + 2g
    const double ds = volume_mm3 / (kerf * h);
    state_.kerf_debris = std::min(1.0, state_.kerf_debris + p.wire_kerf_debris_per_mm * ds);
    if (plane_.active()) {  // the field takes it; depth_mm() counts the cut length it makes
      plane_pending_mm3_ += volume_mm3;
      hole_bottom_mm_ -= ds;
      state_.debris = std::min(1.0, state_.debris + p.debris_kappa * volume_mm3 / v_gap);
      return;
    }
    double s = depth_mm() + ds;
    if (s >= p.wire_hole_from_mm && s < p.wire_hole_to_mm) s = p.wire_hole_to_mm;  // no material
    if (p.wire_cavity_to_mm > p.wire_cavity_from_mm && depth_mm() < p.wire_cavity_to_mm &&
        s >= p.wire_cavity_to_mm) {  // the centre part meets the cavity's stagnant dielectric
      state_.kerf_debris =
          std::min(1.0, state_.kerf_debris + cavity_centre_fraction(s) * p.wire_cavity_debris);
    }
    hole_bottom_mm_ = -s;
  } else {
    if (away_) start_fresh_hole();  // the first crater away from the kept hole: a new one
    hole_started_ = true;
    if (site < 0) {
      hole_bottom_mm_ -= volume_mm3 / area_front_mm2_;
    } else {
      const auto j = static_cast<std::size_t>(site);
      const double a = wall_r_mm_[j] * 2.0 * std::numbers::pi / static_cast<double>(kWallBins) *
                       p.near_tip_zone_mm;
      wall_r_mm_[j] += volume_mm3 / a;
    }
    wear_length_mm_ += wear_mm3 / area_electrode_mm2_;
  }
  state_.debris = std::min(1.0, state_.debris + p.debris_kappa * volume_mm3 / v_gap);
}

void Plant::track_hole() noexcept {
  if (tool_ == Tool::kWire) return;
  const double x = axes_[0].position_mm(), y = axes_[1].position_mm();
  if (!hole_started_) {  // nothing eroded yet
    hole_cx_mm_ = x;
    hole_cy_mm_ = y;
    return;
  }
  if (tool_ != Tool::kTube) return;  // a sinking electrode stays over its cavity
  // Above the surface the electrode may leave the hole, and come back to it, sideways.
  const double tip_z = axes_[2].position_mm() + wear_length_mm_;
  if (tip_z > 0.0) away_ = std::hypot(x - hole_cx_mm_, y - hole_cy_mm_) > params_.hole_d_mm;
}

void Plant::start_fresh_hole() noexcept {
  hole_bottom_mm_ = 0.0;
  wall_r_mm_.fill(params_.hole_d_mm / 2.0);
  hole_started_ = false;
  away_ = false;
  hole_cx_mm_ = axes_[0].position_mm();
  hole_cy_mm_ = axes_[1].position_mm();
}

}  // namespace edm::sim
