#include "edm/hal/sim_component.hpp"

#include <array>

namespace edm::hal {

namespace {

constexpr std::array<const char*, 5> kClass{"open", "normal", "transient-arc", "stable-arc",
                                            "short"};

}  // namespace

struct SimComponent::Pins {
  PinSlot n[5], td_sum_ns, td_count, ratio[5], gap_voltage, short_now, hist_open, hist_short,
      hist_arc, rab;
  PinSlot pos_fb[3], ref[3], contact, drive_fault, heartbeat;
  PinSlot vel_cmd[3], gen_arm, gen_on, polarity_positive, on_time_us, off_time_us, arc_off_time_us,
      servo_ref_v, flushing_on, flushing_strength, rotation_on, touch_mode, pos_set[3],
      pos_value[3], plc_heartbeat;
  PinSlot depth, wall, electrode, hole_x, hole_y;
};

SimComponent::SimComponent(const SimComponentOptions& o, std::string& error)
    : opt_(o), pins_(std::make_unique<Pins>()) {
  auto params = sim::SimParams::preset(o.preset);
  if (!params) {
    error = "unknown preset '" + o.preset + "'";
    return;
  }
  params->wall_sparks = o.wall_sparks;
  plant_ = std::make_unique<sim::Plant>(*params, o.seed);
  if (error = comp_.open(o.name); !error.empty()) return;
  Pins& p = *pins_;
  const auto out = [&](const std::string& n, HalType t, PinSlot& s) {
    if (error.empty()) error = comp_.add_pin(n, t, HalDir::kOut, s);
  };
  const auto in = [&](const std::string& n, HalType t, PinSlot& s) {
    if (error.empty()) error = comp_.add_pin(n, t, HalDir::kIn, s);
  };
  for (std::size_t k = 0; k < 5; ++k) {
    out(std::string("n-") + kClass[k], HalType::kU32, p.n[k]);
    out(std::string("ratio-") + kClass[k], HalType::kFloat, p.ratio[k]);
  }
  out("td-sum-ns", HalType::kU32, p.td_sum_ns);
  out("td-count", HalType::kU32, p.td_count);
  out("gap-voltage", HalType::kFloat, p.gap_voltage);
  out("short", HalType::kBit, p.short_now);
  out("hist-open", HalType::kU32, p.hist_open);
  out("hist-short", HalType::kU32, p.hist_short);
  out("hist-arc", HalType::kU32, p.hist_arc);
  out("rab", HalType::kFloat, p.rab);
  const char* axis[3] = {"x", "y", "z"};
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string n = axis[a];
    out(n + "-pos-fb", HalType::kFloat, p.pos_fb[a]);
    out("ref-" + n, HalType::kBit, p.ref[a]);
    in(n + "-vel-cmd", HalType::kFloat, p.vel_cmd[a]);
    in("pos-set-" + n, HalType::kBit, p.pos_set[a]);
    in("pos-value-" + n, HalType::kFloat, p.pos_value[a]);
  }
  out("contact", HalType::kBit, p.contact);
  out("drive-fault", HalType::kBit, p.drive_fault);
  out("heartbeat", HalType::kU32, p.heartbeat);
  in("gen-arm", HalType::kBit, p.gen_arm);
  in("gen-on", HalType::kBit, p.gen_on);
  in("polarity-positive", HalType::kBit, p.polarity_positive);
  in("on-time-us", HalType::kFloat, p.on_time_us);
  in("off-time-us", HalType::kFloat, p.off_time_us);
  in("arc-off-time-us", HalType::kFloat, p.arc_off_time_us);
  in("servo-ref-v", HalType::kFloat, p.servo_ref_v);
  in("flushing-on", HalType::kBit, p.flushing_on);
  in("flushing-strength", HalType::kFloat, p.flushing_strength);
  in("rotation-on", HalType::kBit, p.rotation_on);
  in("touch-mode", HalType::kBit, p.touch_mode);
  in("plc-heartbeat", HalType::kU32, p.plc_heartbeat);
  out("truth.depth-mm", HalType::kFloat, p.depth);
  out("truth.wall-radius-mm", HalType::kFloat, p.wall);
  out("truth.electrode-mm", HalType::kFloat, p.electrode);
  out("truth.hole-work-x-mm", HalType::kFloat, p.hole_x);
  out("truth.hole-work-y-mm", HalType::kFloat, p.hole_y);
  if (!error.empty()) return;
  // An unconnected flushing-on/-strength pin means flushing as the simulator's driver defaults.
  pin_write(p.flushing_on, 1.0);
  pin_write(p.flushing_strength, 1.0);
  step(std::chrono::nanoseconds(0));
  error = comp_.ready();
}

SimComponent::~SimComponent() = default;

void SimComponent::step(std::chrono::nanoseconds t) noexcept {
  Pins& p = *pins_;
  const std::uint32_t beat = pin_read_u32(p.plc_heartbeat);
  if (beat != plc_beat_) {
    plc_beat_ = beat;
    plc_seen_ = true;
    plc_last_ = t;
  }
  const bool lost = plc_seen_ && t - plc_last_ > opt_.plc_timeout;
  if (lost && !plc_lost_) plant_->enter_safe_state();
  plc_lost_ = lost;
  sim::PlantCommands c;
  c.vx_mm_s = lost ? 0.0 : pin_read(p.vel_cmd[0]);
  c.vy_mm_s = lost ? 0.0 : pin_read(p.vel_cmd[1]);
  c.vz_mm_s = lost ? 0.0 : pin_read(p.vel_cmd[2]);
  c.generator_armed = !lost && pin_read_u32(p.gen_arm) != 0U;
  c.generator_on = !lost && pin_read_u32(p.gen_on) != 0U;
  c.polarity_positive = pin_read_u32(p.polarity_positive) != 0U;
  c.on_time_us = pin_read(p.on_time_us);
  c.off_time_us = pin_read(p.off_time_us);
  c.arc_off_time_us = pin_read(p.arc_off_time_us);
  c.servo_ref_v = lost ? 0.0 : pin_read(p.servo_ref_v);
  c.flushing_on = pin_read_u32(p.flushing_on) != 0U;
  c.flushing_strength = pin_read(p.flushing_strength);
  c.rotation_on = pin_read_u32(p.rotation_on) != 0U;
  c.touch_mode = pin_read_u32(p.touch_mode) != 0U;
  plant_->set_commands(c);
  for (int a = 0; a < 3; ++a) {  // a drive's "set actual position", on the rising edge
    const bool set = pin_read_u32(p.pos_set[a]) != 0U;
    if (set && !pos_set_before_[a]) plant_->set_encoder_mm(a, pin_read(p.pos_value[a]));
    pos_set_before_[a] = set;
  }
  plant_->advance_to(t);
  const sim::CycleSensors s = plant_->take_sensors();
  const sim::PlantState& st = plant_->state();
  std::int64_t total_ns = 0;
  for (std::size_t k = 0; k < 5; ++k) {
    counters_[k] += static_cast<std::uint32_t>(s.count[k]);  // wraps mod 2^32, as an FPGA's
    pin_write_u32(p.n[k], counters_[k]);
    total_ns += s.time_ns[k];
  }
  for (std::size_t k = 0; k < 5; ++k) {
    pin_write(p.ratio[k], total_ns > 0
                              ? static_cast<double>(s.time_ns[k]) / static_cast<double>(total_ns)
                              : 0.0);
  }
  counters_[5] += static_cast<std::uint32_t>(s.td_sum_ns);
  counters_[6] += static_cast<std::uint32_t>(s.td_count);
  pin_write_u32(p.td_sum_ns, counters_[5]);
  pin_write_u32(p.td_count, counters_[6]);
  pin_write(p.gap_voltage, s.mean_gap_voltage_v);
  pin_write(p.short_now, st.last_class == sim::PulseClass::kShort ? 1.0 : 0.0);
  pin_write_u32(p.hist_open, st.history_open);
  pin_write_u32(p.hist_short, st.history_short);
  pin_write_u32(p.hist_arc, st.history_arc);
  pin_write(p.rab, st.rab);
  const double pos[3] = {st.x_mm, st.y_mm, st.z_mm};
  const bool ref[3] = {st.ref_x, st.ref_y, st.ref_z};
  for (std::size_t a = 0; a < 3; ++a) {
    pin_write(p.pos_fb[a], pos[a]);
    pin_write(p.ref[a], ref[a] ? 1.0 : 0.0);
  }
  pin_write(p.contact, st.touch_contact ? 1.0 : 0.0);
  pin_write(p.drive_fault, st.wire_broken ? 1.0 : 0.0);
  pin_write(p.depth, st.depth_mm);
  pin_write(p.wall, st.wall_radius_mm);
  pin_write(p.electrode, st.electrode_length_mm);
  pin_write(p.hole_x, st.hole_work_x_mm);
  pin_write(p.hole_y, st.hole_work_y_mm);
  ++steps_;
  pin_write_u32(p.heartbeat, static_cast<std::uint32_t>(steps_));  // last: the step is complete
}

}  // namespace edm::hal
