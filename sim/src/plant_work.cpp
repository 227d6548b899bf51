#include "edm/sim/plant.hpp"

// The work on the machine and the operator functions it serves (docs/simulator.md §3a): machine
// coordinates and encoders, the reference switches, touch sensing, the hole set from outside.
// With the default parameters none of this changes what the plant did before edm-sim-params/8.

#include <algorithm>
#include <cmath>

#include "edm/sim/random.hpp"

namespace edm::sim {

void Plant::init_work() noexcept {
  const auto& p = params_;
  // reading = position − bias; z's position is the plant's (surface at 0), machine Z is
  // z + work_surface_z_mm. 0 − 0 = +0: the defaults keep a reading's bits.
  enc_bias_mm_ = {p.encoder_offset_x_mm, p.encoder_offset_y_mm,
                  p.encoder_offset_z_mm - p.work_surface_z_mm};
  ref_pos_mm_ = {p.ref_x_mm, p.ref_y_mm, p.ref_z_mm - p.work_surface_z_mm};
  for (std::size_t a = 0; a < 3; ++a) {
    ref_trip_mm_[a] =
        ref_pos_mm_[a] + p.ref_repeat_um * 1e-3 * normal(seed_, Stream::kRefSwitch, a);
    ref_on_[a] = axes_[a].position_mm() >= ref_trip_mm_[a];
  }
  switch (tool_) {
    case Tool::kTube:
      tool_section_ = {0.0, 0.0, p.tool_od_mm / 2.0, p.tool_od_mm / 2.0, true};
      break;
    case Tool::kBlock:
      tool_section_ = {0.0, 0.0, p.tool_width_mm / 2.0, p.tool_length_mm / 2.0, false};
      break;
    case Tool::kWire: tool_section_ = {0.0, 0.0, p.wire_d_mm / 2.0, p.wire_d_mm / 2.0, true}; break;
  }
  work_.block = {p.work_origin_x_mm + (p.work_x_min_mm + p.work_x_max_mm) / 2.0,
                 p.work_origin_y_mm + (p.work_y_min_mm + p.work_y_max_mm) / 2.0,
                 (p.work_x_max_mm - p.work_x_min_mm) / 2.0,
                 (p.work_y_max_mm - p.work_y_min_mm) / 2.0, false};
  work_.bore = {p.work_origin_x_mm + p.work_bore_x_mm, p.work_origin_y_mm + p.work_bore_y_mm,
                p.work_bore_d_mm / 2.0, p.work_bore_d_mm / 2.0, true};
  touch_threshold_now_um_ = touch_threshold_um(0);
  if (p.hole_depth_mm > 0.0) set_hole_mm(p.hole_x_mm, p.hole_y_mm, p.hole_depth_mm);
}

void Plant::set_encoder_mm(int axis, double reading_mm) noexcept {
  if (axis < 0 || axis > 2) return;
  const auto a = static_cast<std::size_t>(axis);
  enc_bias_mm_[a] = axes_[a].position_mm() - reading_mm;
  publish();
}

void Plant::set_hole_mm(double x_mm, double y_mm, double depth_mm) noexcept {
  depth_mm = std::max(0.0, depth_mm);
  hole_bottom_mm_ = -depth_mm;
  if (tool_ != Tool::kWire) {
    hole_cx_mm_ = x_mm;
    hole_cy_mm_ = y_mm;
    hole_started_ = depth_mm > 0.0;
    wall_r_mm_.fill(tool_ == Tool::kTube ? params_.hole_d_mm / 2.0 : 0.0);
    away_ = tool_ == Tool::kTube && hole_started_ &&
            std::hypot(axes_[0].position_mm() - x_mm, axes_[1].position_mm() - y_mm) >
                params_.hole_d_mm;
    if (hold_) axes_[2].reset(hold_gap_um_ * 1e-3 + bottom_mm() - wear_length_mm_);
  }
  publish();
}

void Plant::update_ref_switches() noexcept {
  const double sd_mm = params_.ref_repeat_um * 1e-3;
  for (std::size_t a = 0; a < 3; ++a) {
    const double x = axes_[a].position_mm();
    if (!ref_on_[a]) {
      ref_on_[a] = x >= ref_trip_mm_[a];
    } else if (x < ref_trip_mm_[a] - params_.ref_hysteresis_um * 1e-3) {
      // Released: the next trip happens at a point of its own (the switch's repeatability).
      ref_on_[a] = false;
      const std::uint64_t k = ++ref_trips_[a];
      ref_trip_mm_[a] = ref_pos_mm_[a] + sd_mm * normal(seed_, Stream::kRefSwitch, 3 * k + a);
    }
  }
}

double Plant::touch_release_um() const noexcept {
  return params_.touch_gap_um + 4.0 * params_.touch_noise_um;
}

double Plant::touch_threshold_um(std::uint64_t event) const noexcept {
  const auto& p = params_;
  const double t = p.touch_gap_um + p.touch_noise_um * normal(seed_, Stream::kTouch, event);
  return std::clamp(t, 0.0, touch_release_um());
}

double Plant::mean_wall_radius_mm() const noexcept {
  double r = 0.0;
  for (double w : wall_r_mm_) r += w;
  return r / static_cast<double>(kWallBins);
}

double Plant::touch_distance_um() const noexcept {
  const auto& p = params_;
  if (plane_.active()) {  // the wire spans the plate: its plan-view clearance
    return std::max(0.0, plane_.clearance_mm(axes_[0].position_mm(), axes_[1].position_mm()) -
                             p.wire_d_mm / 2.0) *
           1e3;
  }
  Section tool = tool_section_;
  tool.x_mm = axes_[0].position_mm();
  tool.y_mm = axes_[1].position_mm();
  WorkSolid work = work_;
  if (tool_ != Tool::kWire && hole_started_ && hole_bottom_mm_ < 0.0) {
    const double hw =
        tool_ == Tool::kTube ? mean_wall_radius_mm() : p.tool_width_mm / 2.0 + p.side_gap_mm;
    const double hl = tool_ == Tool::kTube ? hw : p.tool_length_mm / 2.0 + p.side_gap_mm;
    work.hole = {hole_cx_mm_, hole_cy_mm_, hw, hl, tool_ == Tool::kTube};
    work.hole_depth_mm = -hole_bottom_mm_;
  }
  return distance_to_work_mm(tool, tip_z_mm(), tool_ == Tool::kWire, work) * 1e3;
}

void Plant::update_touch() noexcept {
  const double d_um = touch_distance_um();
  const bool was = touch_contact_;
  if (!touch_contact_) {
    touch_contact_ = d_um <= touch_threshold_now_um_;
  } else if (d_um > touch_release_um()) {
    // The contact event is over; the next one senses at a threshold of its own.
    touch_contact_ = false;
    touch_threshold_now_um_ = touch_threshold_um(++touch_events_);
  }
  if (touch_contact_ != was && phase_ == Phase::kIdle) phase_voltage_v_ = idle_voltage_v();
}

void Plant::set_touch_mode(bool on) noexcept {
  if (on) {
    update_touch();
  } else if (touch_contact_) {
    touch_contact_ = false;
    touch_threshold_now_um_ = touch_threshold_um(++touch_events_);
  }
  if (phase_ == Phase::kIdle) phase_voltage_v_ = idle_voltage_v();
}

double Plant::idle_voltage_v() const noexcept {
  return cmd_.touch_mode && !touch_contact_ ? params_.touch_voltage_v : 0.0;
}

}  // namespace edm::sim
