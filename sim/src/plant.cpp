#include "edm/sim/plant.hpp"

// The plant's pulse engine: phases, pulses, axes, sensors. The tool geometry is plant_geometry.cpp.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "edm/sim/random.hpp"

namespace edm::sim {

namespace {

constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();

std::int64_t to_ns(double us) noexcept { return std::llround(us * 1e3); }
std::size_t idx(PulseClass c) noexcept { return static_cast<std::size_t>(c); }
bool is_arc(PulseClass c) noexcept {
  return c == PulseClass::kTransientArc || c == PulseClass::kStableArc;
}

const SimParams& validated(const SimParams& p) {
  const auto errs = p.validate();
  if (errs.empty()) return p;
  std::string msg = "invalid simulator parameters:";
  for (const auto& e : errs) msg += " " + e.field + ": " + e.message + ";";
  throw std::invalid_argument(msg);
}

}  // namespace

Plant::Plant(const SimParams& params, std::uint64_t seed)
    : params_(validated(params)), model_(params_), seed_(seed) {
  const auto& p = params_;
  tool_ = p.tool_kind == "block" ? Tool::kBlock : p.tool_kind == "wire" ? Tool::kWire : Tool::kTube;
  const double pi = std::numbers::pi;
  double wall_r = 0.0;
  switch (tool_) {
    case Tool::kTube:
      area_front_mm2_ = pi / 4.0 * p.hole_d_mm * p.hole_d_mm;  // the core breaks out with it
      area_electrode_mm2_ = pi / 4.0 * (p.tool_od_mm * p.tool_od_mm - p.tool_id_mm * p.tool_id_mm);
      side_area_mm2_ = pi * p.hole_d_mm * p.near_tip_zone_mm;
      wall_r = p.hole_d_mm / 2.0;
      break;
    case Tool::kBlock:
      area_front_mm2_ =
          (p.tool_width_mm + 2.0 * p.side_gap_mm) * (p.tool_length_mm + 2.0 * p.side_gap_mm);
      area_electrode_mm2_ = p.tool_width_mm * p.tool_length_mm;
      side_area_mm2_ = 2.0 * (p.tool_width_mm + p.tool_length_mm) * p.near_tip_zone_mm;
      break;
    case Tool::kWire: {
      std::string why;
      profile_ = *ThicknessProfile::make(p.wire_thickness_profile, &why);  // validated above
      area_electrode_mm2_ = 1.0;                                           // no wear
      if (p.wire_plane) {
        plane_ = WirePlane(WirePlaneGeometry{
            p.wire_plate_x_min_mm, p.wire_plate_x_max_mm, p.wire_plate_y_min_mm,
            p.wire_plate_y_max_mm, p.wire_plate_mm, p.wire_grid_um * 1e-3, p.wire_start_hole_x_mm,
            p.wire_start_hole_y_mm, p.wire_start_hole_d_mm, p.wire_step_x_mm, p.wire_step_mm,
            p.wire_void_x_mm, p.wire_void_y_mm, p.wire_void_d_mm, p.wire_void_height_mm});
        plane_erode_ns_ = std::max<std::int64_t>(1, to_ns(p.wire_erode_ms * 1e3));
      }
      break;
    }
  }
  for (std::size_t j = 0; j < kWallBins; ++j) {
    const double phi = 2.0 * pi * static_cast<double>(j) / static_cast<double>(kWallBins);
    wall_r_mm_[j] = wall_r;
    wall_cos_[j] = std::cos(phi);
    wall_sin_[j] = std::sin(phi);
  }
  const AxisLimits xy{p.axis_wn_rad_s, p.axis_zeta, p.v_max_mm_s, p.v_max_mm_s, p.a_max_mm_s2};
  AxisLimits z = xy;
  z.v_pos_max_mm_s = p.v_jump_mm_s;
  axes_ = {Axis(xy), Axis(xy), Axis(z)};
  axes_[0].reset(p.start_x_mm);
  axes_[1].reset(p.start_y_mm);
  hole_cx_mm_ = p.start_x_mm;
  hole_cy_mm_ = p.start_y_mm;
  if (tool_ != Tool::kWire && p.initial_depth_mm > 0.0) {
    hole_bottom_mm_ = -p.initial_depth_mm;
    hole_started_ = true;
  }
  axes_[2].reset(p.start_gap_um * 1e-3 + hole_bottom_mm_);
  jump_low_z_mm_ = axes_[2].position_mm();
  axis_step_ns_ = std::max<std::int64_t>(1, to_ns(p.axis_step_us));
  working_gap_um_ = model_.no_ignition_gap_um(p.wait_time_us, 0.0);
  contact_ = p.contact_at_depth_mm > 0.0 ? Contact::kArmed : Contact::kOff;
  rab_ = RabWindow(to_ns(p.rab_window_ms * 1e3));
  wire_monitor_ = WireBreakMonitor(
      to_ns(p.wire_break_current_ms * 1e3), p.wire_break_rab, to_ns(p.wire_break_rab_ms * 1e3),
      p.wire_break_rab_width, to_ns(p.wire_break_rab_tau_ms * 1e3),
      wire_break_threshold(seed_, static_cast<int>(p.wire_break_rab_shape)));
  init_work();
  publish();
}

bool Plant::generator_enabled() const noexcept {
  return cmd_.generator_armed && cmd_.generator_on && !cmd_.touch_mode && !state_.wire_broken;
}

void Plant::set_commands(const PlantCommands& c) noexcept {
  const bool was = generator_enabled();
  const bool was_touch = cmd_.touch_mode;
  cmd_ = c;
  const std::int64_t now = state_.now.count();
  if (c.touch_mode != was_touch) {
    account(now);
    set_touch_mode(c.touch_mode);
  }
  if (!was && generator_enabled() && phase_ == Phase::kIdle && !paused_) start_pulse(now);
  if (was && !generator_enabled()) set_idle(now);
}

void Plant::account(std::int64_t until_ns) noexcept {
  const std::int64_t dt = until_ns - accounted_ns_;
  if (dt <= 0) return;
  if (phase_ != Phase::kIdle) sensors_.time_ns[idx(cls_)] += dt;
  sensor_volt_ns_ += phase_voltage_v_ * static_cast<double>(dt);
  sensor_elapsed_ns_ += dt;
  const double a = 1.0 - std::exp(-static_cast<double>(dt) / (params_.mean_voltage_tau_ms * 1e6));
  state_.gap_voltage_filtered_v += (phase_voltage_v_ - state_.gap_voltage_filtered_v) * a;
  accounted_ns_ = until_ns;
}

void Plant::step_axes(std::int64_t t_ns) noexcept {
  const double dt = static_cast<double>(t_ns - axis_time_ns_) * 1e-9;
  axis_time_ns_ = t_ns;
  axes_[0].step(cmd_.vx_mm_s, dt);
  axes_[1].step(cmd_.vy_mm_s, dt);
  track_hole();
  if (hold_) {
    axes_[2].reset(hold_gap_um_ * 1e-3 + bottom_mm() - wear_length_mm_);
  } else {
    double vz = cmd_.vz_mm_s;
    if (cmd_.servo_ref_v > 0.0 &&
        !plane_.active()) {  // the machine's own servo: advance while U_av > reference
      vz -= params_.servo_gain_mm_s_per_v * (state_.gap_voltage_filtered_v - cmd_.servo_ref_v);
    }
    axes_[2].step(vz, dt);
  }
  if (plane_.active() && plane_pending_mm3_ > 0.0 &&
      t_ns - plane_eroded_at_ns_ >= plane_erode_ns_) {
    plane_.erode(axes_[0].position_mm(), axes_[1].position_mm(),
                 params_.wire_d_mm / 2.0 + params_.wire_reach_um * 1e-3, plane_pending_mm3_);
    plane_pending_mm3_ = 0.0;
    plane_eroded_at_ns_ = t_ns;
  }
  track_short_events();
  update_ref_switches();
  if (cmd_.touch_mode) update_touch();
  const double z = axes_[2].position_mm();
  const double gap = front_gap_um(z);
  const double h_flush = tool_ == Tool::kWire ? 0.0 : depth_mm();
  state_.debris = model_.debris_after(state_.debris,
                                      model_.flush_rate_per_s(gap, h_flush, flush_effective()), dt);
  if (tool_ == Tool::kWire && state_.kerf_debris > 0.0) {
    const auto& p = params_;
    const double tau =
        p.wire_kerf_flush_s * std::pow(cut_thickness_mm() / 10.0, p.wire_kerf_flush_exp);
    const double r = std::clamp(gap / p.flush_gap_ref_um, 0.0, 1.0);
    state_.kerf_debris *= std::exp(-flush_effective() * r * r * r * dt / tau);
  }
  if (params_.jump_eps > 0.0) {  // a retract longer than Δz_j flushes once per jump
    jump_low_z_mm_ = std::min(jump_low_z_mm_, z);
    if (jump_armed_ && z - jump_low_z_mm_ > params_.jump_dz_mm) {
      state_.debris *= 1.0 - params_.jump_eps;
      jump_armed_ = false;
    } else if (!jump_armed_ && axes_[2].velocity_mm_s() <= 0.0) {
      jump_armed_ = true;
      jump_low_z_mm_ = z;
    }
  }
}

void Plant::set_idle(std::int64_t t_ns) noexcept {
  account(t_ns);
  phase_ = Phase::kIdle;
  phase_voltage_v_ = idle_voltage_v();
  phase_end_ns_ = kNever;
}

void Plant::enter_phase(Phase ph, std::int64_t t_ns, std::int64_t dur_ns) noexcept {
  phase_ = ph;
  phase_end_ns_ = t_ns + dur_ns;
  phase_voltage_v_ = ph == Phase::kWait ? params_.open_voltage_v
                     : ph == Phase::kOn ? on_voltage_v_
                                        : 0.0;
  if (dur_ns <= 0) on_phase_end(t_ns);  // zero-length phase: go on at once (OFF is never 0)
}

void Plant::on_phase_end(std::int64_t t_ns) noexcept {
  switch (phase_) {
    case Phase::kWait: enter_phase(Phase::kOn, t_ns, on_ns_); break;
    case Phase::kOn: enter_phase(Phase::kOff, t_ns, off_ns_); break;
    case Phase::kOff: start_pulse(t_ns); break;
    case Phase::kIdle: break;
  }
}

void Plant::update_wire(std::int64_t t_ns) noexcept {
  const std::int64_t dt = t_ns - wire_time_ns_;
  if (dt <= 0) return;
  wire_time_ns_ = t_ns;
  current_sum_a_ *= std::exp(-static_cast<double>(dt) / (params_.mean_current_ema_ms * 1e6));
  if (tool_ != Tool::kWire || state_.wire_broken) return;
  const double f = params_.wire_flush_floor + (1.0 - params_.wire_flush_floor) * flush_effective();
  const double ibk = wire_break_current_a(params_.wire_ibk_ref_a, cut_thickness_mm(), f);
  state_.wire_load = current_sum_a_ / ibk;
  if (wire_monitor_.update(dt, current_sum_a_, ibk, rab_.rab(t_ns))) {
    state_.wire_broken = true;
    set_idle(t_ns);
  }
}

void Plant::start_pulse(std::int64_t t_ns) noexcept {
  update_wire(t_ns);
  if (!generator_enabled()) {
    set_idle(t_ns);
    return;
  }
  if (pulses_this_advance_ >= params_.max_pulses_per_advance) {
    if (!paused_) ++state_.budget_overruns;
    paused_ = true;
    set_idle(t_ns);
    return;
  }
  ++pulses_this_advance_;
  const auto& p = params_;
  const std::uint64_t k = state_.pulses++;
  const double c = std::min(1.0, state_.debris + state_.kerf_debris);  // kerf: wire only

  // The gap(s) at this instant and the median delay; when the wall bins compete, the hazards
  // add (same Weibull shape) and the site is drawn in proportion to A_j τ_j^-k (§6.2 step 5).
  const double gap_front = front_gap_um(tool_z_mm(t_ns));
  double gap = gap_front;
  double median = model_.td_median_us(gap_front, c);
  int site = -1;
  // The wall competes only where there is one: with the tip below the work surface.
  if (tool_ == Tool::kTube && p.wall_sparks && !away_ && tool_z_mm(t_ns) + wear_length_mm_ < 0.0) {
    const double kw = p.weibull_k;
    std::array<double, kWallBins> w{};
    const double w_front = std::isfinite(median) ? area_front_mm2_ * std::pow(median, -kw) : 0.0;
    double sum = w_front;
    for (std::size_t j = 0; j < kWallBins; ++j) {
      const double gj = wall_gap_um(j);
      gap = std::min(gap, gj);
      const double tj = model_.td_median_us(gj, c);
      const double aj = wall_r_mm_[j] * 2.0 * std::numbers::pi / static_cast<double>(kWallBins) *
                        p.near_tip_zone_mm;
      w[j] = std::isfinite(tj) ? aj * std::pow(tj, -kw) : 0.0;
      sum += w[j];
    }
    median = sum > 0.0 ? std::pow(sum / area_front_mm2_, -1.0 / kw)
                       : std::numeric_limits<double>::infinity();
    double pick = uniform(seed_, Stream::kSite, k) * sum - w_front;
    for (std::size_t j = 0; j < kWallBins && pick >= 0.0; ++j) {
      pick -= w[j];
      if (pick < 0.0) site = static_cast<int>(j);
    }
  }

  const PulseInput in{gap,
                      c,
                      median,
                      static_cast<double>(t_ns - last_discharge_end_ns_) * 1e-3,
                      p.wait_time_us,
                      is_arc(state_.last_class)};
  const PulseDraw draw{uniform(seed_, Stream::kDebrisShort, k), uniform(seed_, Stream::kArc, k),
                       uniform(seed_, Stream::kTd, k), uniform(seed_, Stream::kArcTd, k)};
  const ShortCause forced = short_event(t_ns, k, gap_front, c);
  const PulseOutcome out =
      forced == ShortCause::kNone
          ? model_.classify(in, draw)
          : PulseOutcome{PulseClass::kShort, 0.0, forced == ShortCause::kBridge};

  const double on_us = cmd_.on_time_us > 0.0 ? cmd_.on_time_us : p.default_on_time_us;
  const std::int64_t off_ns = std::max<std::int64_t>(
      10, to_ns(cmd_.off_time_us > 0.0 ? cmd_.off_time_us : p.default_off_time_us));
  const std::int64_t arc_off_ns =
      std::max<std::int64_t>(10, cmd_.arc_off_time_us > 0.0 ? to_ns(cmd_.arc_off_time_us)
                                 : cmd_.off_time_us > 0.0   ? off_ns
                                                            : to_ns(p.default_arc_off_time_us));
  const std::int64_t td_ns = to_ns(out.td_us);
  const std::int64_t td_q = (td_ns + p.td_quantum_ns / 2) / p.td_quantum_ns * p.td_quantum_ns;
  cls_ = out.cls;
  on_ns_ = to_ns(on_us);
  off_ns_ = arc_off_ns;
  switch (out.cls) {
    case PulseClass::kOpen:
      on_ns_ = 0;
      off_ns_ = off_ns;
      on_voltage_v_ = 0.0;
      break;
    case PulseClass::kNormal:
      off_ns_ = off_ns;
      on_voltage_v_ = p.discharge_voltage_v;
      break;
    case PulseClass::kTransientArc:
    case PulseClass::kStableArc: on_voltage_v_ = p.arc_voltage_v; break;
    case PulseClass::kShort:
      if (out.debris_short) on_ns_ = to_ns(p.debris_short_us);
      on_voltage_v_ = p.short_voltage_v;
      break;
  }

  if (out.cls == PulseClass::kNormal || is_arc(out.cls)) {
    const bool pos = cmd_.polarity_positive;
    double v = model_.spark_volume_mm3(p.peak_current_a, on_us, c,
                                       normal(seed_, Stream::kRemovalScatter, k)) *
               (pos ? p.removal_scale_positive : 1.0);
    double theta = pos ? p.wear_ratio_positive : p.wear_ratio;
    if (is_arc(out.cls)) {
      v *= p.arc_removal_ratio;
      theta *= p.arc_wear_factor;
    }
    remove(v, theta * v, gap_front, site);
    current_sum_a_ += p.peak_current_a * on_us * 1e-3 / p.mean_current_ema_ms;
    last_discharge_end_ns_ = t_ns + td_ns + on_ns_;
    sensors_.td_sum_ns += td_q;
    ++sensors_.td_count;
  }
  ++sensors_.count[idx(out.cls)];
  state_.history_open = (state_.history_open << 1) | (out.cls == PulseClass::kOpen ? 1U : 0U);
  state_.history_short = (state_.history_short << 1) | (out.cls == PulseClass::kShort ? 1U : 0U);
  state_.history_arc = (state_.history_arc << 1) | (is_arc(out.cls) ? 1U : 0U);
  rab_.add(t_ns, out.cls == PulseClass::kShort || is_arc(out.cls));
  state_.last_class = out.cls;
  state_.last_td_ns = td_q;
  enter_phase(Phase::kWait, t_ns, td_ns);
}

void Plant::advance_to(edm::rt::TimePoint t) noexcept {
  const std::int64_t end = t.count();
  const std::int64_t now = state_.now.count();
  if (end <= now) return;
  pulses_this_advance_ = 0;
  if (paused_) {  // the budget ran out in the previous advance: resume here
    paused_ = false;
    if (generator_enabled() && phase_ == Phase::kIdle) start_pulse(now);
  }
  while (true) {
    const std::int64_t next_axis = axis_time_ns_ + axis_step_ns_;
    const std::int64_t next_event = phase_ == Phase::kIdle ? kNever : phase_end_ns_;
    if (std::min(next_axis, next_event) > end) break;
    if (next_axis <= next_event) {
      account(next_axis);
      step_axes(next_axis);
    } else {
      account(next_event);
      on_phase_end(next_event);
    }
  }
  account(end);
  update_wire(end);
  state_.now = t;
  publish();
}

CycleSensors Plant::take_sensors() noexcept {
  CycleSensors s = sensors_;
  s.mean_gap_voltage_v =
      sensor_elapsed_ns_ > 0 ? sensor_volt_ns_ / static_cast<double>(sensor_elapsed_ns_) : 0.0;
  sensors_ = {};
  sensor_volt_ns_ = 0.0;
  sensor_elapsed_ns_ = 0;
  return s;
}

void Plant::enter_safe_state() noexcept {
  cmd_.generator_on = false;
  cmd_.vx_mm_s = cmd_.vy_mm_s = cmd_.vz_mm_s = 0.0;
  set_idle(state_.now.count());
}

void Plant::hold_gap(double gap_um) noexcept {
  hold_ = true;
  hold_gap_um_ = gap_um;
  axes_[2].reset(gap_um * 1e-3 + bottom_mm() - wear_length_mm_);
  publish();
}

void Plant::release_gap() noexcept { hold_ = false; }

void Plant::set_depth_mm(double h) noexcept {
  hole_bottom_mm_ = -h;
  hole_started_ = hole_started_ || h > 0.0;
  away_ = false;  // the hole under the electrode
  if (hold_) axes_[2].reset(hold_gap_um_ * 1e-3 + bottom_mm() - wear_length_mm_);
  publish();
}

void Plant::break_wire() noexcept {
  if (tool_ != Tool::kWire) return;
  state_.wire_broken = true;
  set_idle(state_.now.count());
  publish();
}

void Plant::thread_wire() noexcept {
  state_.wire_broken = false;
  publish();
}

void Plant::set_debris(double c) noexcept {
  state_.debris = std::clamp(c, 0.0, 1.0);
  publish();
}

void Plant::set_electrode_length_mm(double mm) noexcept {
  wear_length_mm_ = params_.electrode_length_mm - mm;
  if (hold_) axes_[2].reset(hold_gap_um_ * 1e-3 + bottom_mm() - wear_length_mm_);
  publish();
}

void Plant::publish() noexcept {
  const double q = params_.encoder_um * 1e-3;
  auto quantise = [q](double x) { return q > 0.0 ? std::round(x / q) * q : x; };
  // bias 0 (the defaults) leaves a position's bits as they are, −0 included
  state_.x_mm = quantise(axes_[0].position_mm() - enc_bias_mm_[0]);
  state_.y_mm = quantise(axes_[1].position_mm() - enc_bias_mm_[1]);
  state_.z_mm = quantise(axes_[2].position_mm() - enc_bias_mm_[2]);
  state_.machine_x_mm = axes_[0].position_mm();
  state_.machine_y_mm = axes_[1].position_mm();
  state_.machine_z_mm = axes_[2].position_mm() + params_.work_surface_z_mm;
  state_.vz_mm_s = axes_[2].velocity_mm_s();
  state_.depth_mm = depth_mm();
  // Away from its hole the electrode is over a fresh one (the bins as a new hole would have them).
  double r = 0.0;
  for (double w : wall_r_mm_) r += away_ ? params_.hole_d_mm / 2.0 : w;
  state_.wall_radius_mm = r / static_cast<double>(kWallBins);
  state_.gap_um = front_gap_um(axes_[2].position_mm());
  state_.electrode_length_mm = params_.electrode_length_mm - wear_length_mm_;
  state_.mean_current_a = current_sum_a_;
  state_.flush_effective = flush_effective();
  state_.rab = rab_.rab(state_.now.count());
  state_.contact =
      contact_ == Contact::kMet && (tip_z_mm() - contact_tip_mm_) * 1e3 < params_.contact_clear_um;
  state_.ref_x = ref_on_[0];
  state_.ref_y = ref_on_[1];
  state_.ref_z = ref_on_[2];
  state_.touch_contact = cmd_.touch_mode && touch_contact_;
  state_.hole_depth_mm = -hole_bottom_mm_;
  state_.hole_x_mm = hole_cx_mm_;
  state_.hole_y_mm = hole_cy_mm_;
  state_.hole_work_x_mm = hole_cx_mm_ - params_.work_origin_x_mm;
  state_.hole_work_y_mm = hole_cy_mm_ - params_.work_origin_y_mm;
}

}  // namespace edm::sim
