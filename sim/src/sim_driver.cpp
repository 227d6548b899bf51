#include "edm/sim/sim_driver.hpp"

#include "edm/runtime/clock.hpp"

namespace edm::sim {

namespace rt = edm::rt;

namespace {
// The runtime-writable parameters, in the order of SimDriver::Live.
constexpr std::string_view kLiveNames[] = {"electrode_length_mm", "hole_depth_mm", "hole_x_mm",
                                           "hole_y_mm"};
}  // namespace

void SimDriverParams::visit(rt::ParamVisitor& v) {
  v.param("preset", preset,
          rt::load_time({"", "drill | sink | wire: the defaults of every other parameter"}));
  if (preset != loaded_preset) {
    if (auto p = SimParams::preset(preset)) {
      plant = *p;
    }
    loaded_preset = preset;
  }
  v.param("seed", seed,
          rt::load_time({"", "random seed (every variate is keyed by seed, stream, pulse)",
                         rt::kNonNegative}));
  plant.visit(v);
}

std::vector<rt::ParamError> SimDriverParams::validate() const {
  if (!SimParams::preset(preset)) {
    std::string names;
    for (const auto& n : preset_names()) {
      names += (names.empty() ? "" : ", ") + n;
    }
    return {{"preset", "unknown preset '" + preset + "' (presets: " + names + ")"}};
  }
  return plant.cross_field_errors();  // the plant's fields were checked against their ranges
}

std::vector<rt::ParamError> SimDriver::configure(const rt::BlockSetup& setup) {
  if (setup.period.count() <= 0) {
    return {{"", "the simulator needs an I/O task with a period > 0"}};
  }
  plant_ = std::make_unique<Plant>(params_.plant, static_cast<std::uint64_t>(params_.seed));
  started_ = false;
  for (bool& b : pos_set_before_) b = false;
  // The indices the registry uses for the live parameters (visit order of SimDriverParams).
  struct Find final : rt::ParamVisitor {
    std::size_t n = 0;
    std::size_t at[kLiveCount]{};
    void on_param(std::string_view name, rt::ParamRef, rt::ParamSpec) override {
      for (std::size_t k = 0; k < kLiveCount; ++k) {
        if (name == kLiveNames[k]) at[k] = n;
      }
      ++n;
    }
  } find;
  SimDriverParams copy = params_;
  copy.visit(find);
  for (std::size_t k = 0; k < kLiveCount; ++k) {
    live_index_[k] = find.at[k];
  }
  publish_live();
  return {};
}

void SimDriver::publish_live() noexcept {
  const PlantState& st = plant_->state();
  const double v[kLiveCount] = {st.electrode_length_mm, st.hole_depth_mm, st.hole_x_mm,
                                st.hole_y_mm};
  for (std::size_t k = 0; k < kLiveCount; ++k) {
    live_[k].store(v[k], std::memory_order_relaxed);
  }
}

void SimDriver::apply_param(std::size_t index, const rt::ParamValue& v) noexcept {
  changed_param_ = index;
  BlockWithParams::apply_param(index, v);
}

void SimDriver::params_changed() noexcept {
  if (!plant_) return;
  const SimParams& p = params_.plant;
  const PlantState& st = plant_->state();
  // One figure at a time, the others as the plant has them now: a retain store restores the
  // three one after the other, and the live hole may have moved since the config was read.
  if (changed_param_ == live_index_[kElectrode]) {
    plant_->set_electrode_length_mm(p.electrode_length_mm);
  } else if (changed_param_ == live_index_[kHoleDepth]) {
    plant_->set_hole_mm(st.hole_x_mm, st.hole_y_mm, p.hole_depth_mm);
  } else if (changed_param_ == live_index_[kHoleX]) {
    plant_->set_hole_mm(p.hole_x_mm, st.hole_y_mm, st.hole_depth_mm);
  } else if (changed_param_ == live_index_[kHoleY]) {
    plant_->set_hole_mm(st.hole_x_mm, p.hole_y_mm, st.hole_depth_mm);
  }
  publish_live();
}

rt::ParamValue SimDriver::read_param(std::size_t index) const {
  for (std::size_t k = 0; plant_ && k < kLiveCount; ++k) {
    if (index == live_index_[k]) {
      return rt::ParamValue::of_real(live_[k].load(std::memory_order_relaxed));
    }
  }
  return BlockWithParams::read_param(index);
}

void SimDriver::activate() noexcept { started_ = false; }

bool SimDriver::set_seed(std::uint64_t seed) {
  params_.seed = static_cast<std::int64_t>(seed & 0x7fffffffffffffffULL);
  return true;
}

struct SimDriver::StateOutput {
  std::string_view name;
  std::string_view unit;
  rt::Output<double> SimDriver::*pin;
  double PlantState::*field;
};

const SimDriver::StateOutput SimDriver::kAxisOutputs[6] = {
    {"x_mm", "mm", &SimDriver::x_mm_, &PlantState::x_mm},
    {"y_mm", "mm", &SimDriver::y_mm_, &PlantState::y_mm},
    {"z_mm", "mm", &SimDriver::z_mm_, &PlantState::z_mm},
    {"electrode_mm", "mm", &SimDriver::electrode_mm_, &PlantState::electrode_length_mm},
    {"depth_mm", "mm", &SimDriver::depth_mm_, &PlantState::depth_mm},
    {"wall_radius_mm", "mm", &SimDriver::wall_radius_mm_, &PlantState::wall_radius_mm}};

const SimDriver::StateOutput SimDriver::kTruthOutputs[4] = {
    {"true_gap_um", "um", &SimDriver::true_gap_um_, &PlantState::gap_um},
    {"true_debris", "1", &SimDriver::true_debris_, &PlantState::debris},
    {"true_kerf_debris", "1", &SimDriver::true_kerf_debris_, &PlantState::kerf_debris},
    {"wire_load", "1", &SimDriver::wire_load_, &PlantState::wire_load}};

void SimDriver::visit_pins(rt::PinVisitor& v) {
  v.output("td_sum_ns", td_sum_ns_, "ns");
  v.output("td_count", td_count_);
  static constexpr const char* kCount[5] = {"n_open", "n_normal", "n_transient_arc", "n_stable_arc",
                                            "n_short"};
  static constexpr const char* kRatio[5] = {"ratio_open", "ratio_normal", "ratio_transient_arc",
                                            "ratio_stable_arc", "ratio_short"};
  for (int k = 0; k < 5; ++k) {
    v.output(kCount[k], n_[k]);
  }
  for (int k = 0; k < 5; ++k) {
    v.output(kRatio[k], ratio_[k], "1");
  }
  v.output("hist_open", hist_open_);
  v.output("hist_short", hist_short_);
  v.output("hist_arc", hist_arc_);
  v.output("rab", rab_, "1");
  v.output("gap_voltage_v", gap_voltage_v_, "V");
  for (const StateOutput& o : kAxisOutputs) {
    v.output(o.name, this->*o.pin, o.unit);
  }
  v.output("wire_broken", wire_broken_);
  v.output("driver_fault", driver_fault_);
  for (const StateOutput& o : kTruthOutputs) {
    v.output(o.name, this->*o.pin, o.unit);
  }
  v.output("ref_x", ref_[0]);
  v.output("ref_y", ref_[1]);
  v.output("ref_z", ref_[2]);
  v.output("contact", contact_);
  v.output("hole_work_x_mm", hole_work_x_mm_, "mm");
  v.output("hole_work_y_mm", hole_work_y_mm_, "mm");

  v.input("vx_cmd", vx_cmd_, "mm/s");
  v.input("vy_cmd", vy_cmd_, "mm/s");
  v.input("vz_cmd", vz_cmd_, "mm/s");
  v.input("gen_arm", gen_arm_);
  v.input("gen_on", gen_on_);
  v.input("polarity_positive", polarity_positive_);
  v.input("on_time_us", on_time_us_, "us");
  v.input("off_time_us", off_time_us_, "us");
  v.input("arc_off_time_us", arc_off_time_us_, "us");
  v.input("servo_ref_v", servo_ref_v_, "V");
  v.input("flushing_on", flushing_on_);
  v.input("flushing_strength", flushing_strength_, "1");
  v.input("rotation_on", rotation_on_);
  v.input("touch_mode", touch_mode_);
  v.input("pos_set_x", pos_set_[0]);
  v.input("pos_set_y", pos_set_[1]);
  v.input("pos_set_z", pos_set_[2]);
  v.input("pos_value_x_mm", pos_value_mm_[0], "mm");
  v.input("pos_value_y_mm", pos_value_mm_[1], "mm");
  v.input("pos_value_z_mm", pos_value_mm_[2], "mm");
}

void SimDriver::read_inputs(const rt::CycleContext& ctx) noexcept {
  // The plant's time line starts at 0 at the first latch: CLOCK_MONOTONIC is days, not 0.
  // Virtual clock: now == the release; real clock: each latch catches the plant up to now.
  const rt::TimePoint now = ctx.clock != nullptr ? ctx.clock->now() : ctx.release;
  if (!started_) {
    origin_ = now;
    started_ = true;
  }
  plant_->advance_to(now - origin_);
  const CycleSensors s = plant_->take_sensors();
  const PlantState& st = plant_->state();
  td_sum_ns_.set(s.td_sum_ns);
  td_count_.set(s.td_count);
  std::int64_t total_ns = 0;
  for (int k = 0; k < 5; ++k) {
    n_[k].set(s.count[k]);
    total_ns += s.time_ns[k];
  }
  for (int k = 0; k < 5; ++k) {
    ratio_[k].set(total_ns > 0 ? static_cast<double>(s.time_ns[k]) / static_cast<double>(total_ns)
                               : 0.0);
  }
  hist_open_.set(st.history_open);
  hist_short_.set(st.history_short);
  hist_arc_.set(st.history_arc);
  rab_.set(st.rab);
  gap_voltage_v_.set(s.mean_gap_voltage_v);
  for (const StateOutput& o : kAxisOutputs) {
    (this->*o.pin).set(st.*o.field);
  }
  publish_live();
  wire_broken_.set(st.wire_broken);
  driver_fault_.set(st.wire_broken);
  for (const StateOutput& o : kTruthOutputs) {
    (this->*o.pin).set(st.*o.field);
  }
  ref_[0].set(st.ref_x);
  ref_[1].set(st.ref_y);
  ref_[2].set(st.ref_z);
  contact_.set(st.touch_contact);
  hole_work_x_mm_.set(st.hole_work_x_mm);
  hole_work_y_mm_.set(st.hole_work_y_mm);
}

void SimDriver::write_outputs(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool estop = ctx.state == rt::MachineState::kEstop;
  PlantCommands c;
  c.vx_mm_s = estop ? 0.0 : vx_cmd_.get();
  c.vy_mm_s = estop ? 0.0 : vy_cmd_.get();
  c.vz_mm_s = estop ? 0.0 : vz_cmd_.get();
  c.generator_armed = !safe && gen_arm_.get();
  c.generator_on = !safe && gen_on_.get();
  c.polarity_positive = polarity_positive_.get();
  c.on_time_us = on_time_us_.get();
  c.off_time_us = off_time_us_.get();
  c.arc_off_time_us = arc_off_time_us_.get();
  c.servo_ref_v = safe ? 0.0 : servo_ref_v_.get();  // no machine servo in FAULT or ESTOP
  c.flushing_on = flushing_on_.get();
  c.flushing_strength = flushing_strength_.get();
  c.rotation_on = rotation_on_.get();
  c.touch_mode = touch_mode_.get();
  plant_->set_commands(c);
  for (int a = 0; a < 3; ++a) {  // a drive's "set actual position", on the rising edge
    const bool set = pos_set_[a].get();
    if (set && !pos_set_before_[a]) plant_->set_encoder_mm(a, pos_value_mm_[a].get());
    pos_set_before_[a] = set;
  }
}

void SimDriver::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  plant_->enter_safe_state();
}

rt::IoFault SimDriver::fault() const noexcept {
  // A broken wire is the process's, not the driver's: io.wire_broken says it, and the
  // supervisor's safety.wire_break makes it alarm 170 with its cause and remedy (every shipped
  // wire config wires it). As a driver fault it came first as alarm 120, "I/O fault".
  return {};
}

void register_sim_driver(rt::DriverRegistry& r) {
  r.add<SimDriver>("sim", "EDM plant simulator (presets drill, sink, wire)");
}

}  // namespace edm::sim
