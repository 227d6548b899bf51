#pragma once
// The EDM plant simulator as the machine's I/O driver (`driver: sim`).
//
// Parameters: `preset` (drill | sink | wire) supplies every default; any SimParams field can be
// overridden by name in `machine.io.params` and is validated like all config (file:line:col);
// `seed` keys every random variate (--seed overrides it).
//
// Process image (io.<pin>), inputs to the runtime — latched at the start of each cycle of the
// I/O task after advancing the plant to the clock's now:
//   td_sum_ns, td_count                 ignition delay sum (10 ns quantum) and count this cycle
//   n_open, n_normal, n_transient_arc, n_stable_arc, n_short   pulses by class this cycle
//   ratio_open … ratio_short            five-state time ratios this cycle (0..1)
//   hist_open, hist_short, hist_arc     last 32 pulses as bitmasks (bit 0 newest)
//   rab                                 (arc + short) / total over the Rab window
//   gap_voltage_v                       mean gap voltage this cycle
//   x_mm, y_mm, z_mm                    encoder positions
//   electrode_mm, depth_mm, wall_radius_mm, wire_broken, driver_fault
//   true_gap_um, true_debris,           the plant's hidden state (for traces, not for control):
//   true_kerf_debris, wire_load         WEDM kerf debris c_k and Ī / I_BK
//   ref_x, ref_y, ref_z                 reference (home) switches
//   contact                             touch_mode and the electrode within the touch gap
//   hole_work_x_mm, hole_work_y_mm      the hole's axis relative to the work's datum (truth)
// outputs from the runtime — latched at the end of each cycle:
//   vx_cmd, vy_cmd, vz_cmd (mm/s, +z away from the work), gen_arm, gen_on, polarity_positive,
//   on_time_us, off_time_us, arc_off_time_us (0 = preset), servo_ref_v (V; > 0 switches on the
//   machine's own gap-voltage servo, which adds −servo_gain_mm_s_per_v·(U_av − servo_ref_v) to
//   vz_cmd; 0 = off), flushing_on, flushing_strength (0..1), rotation_on,
//   touch_mode (no discharges, contact sensing), pos_set_x/_y/_z with pos_value_x_mm/_y_mm/_z_mm
//   (on a rising edge the axis's encoder is set to read the value; the axis does not move)
// x_mm, y_mm, z_mm are encoder readings: machine position − encoder offset (docs/simulator.md §3a).
// Safe state: in FAULT and ESTOP the generator is off whatever the pins say; in ESTOP the axes
// are also held at zero velocity (in FAULT the programs back Z off through vz_cmd).
//
// Retain: `io.electrode_length_mm`, `io.hole_depth_mm`, `io.hole_x_mm` and `io.hole_y_mm` are the
// runtime-writable parameters. They read the plant's live length left and hole; a write (the
// retain store's restore at start, after activate()) sets it, so listing them under
// `retain.variables` carries the electrode and the half-drilled hole across a restart.
//
// RT-safety: read_inputs/write_outputs/enter_safe_state/fault are RT-safe. Thread-safety: the
// I/O task's thread only.

#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/type_registry.hpp"
#include "edm/sim/params.hpp"
#include "edm/sim/plant.hpp"

namespace edm::sim {

struct SimDriverParams {
  std::string preset{"drill"};
  std::int64_t seed{1};
  SimParams plant{};
  std::string loaded_preset;  // which preset `plant` was filled from (not a parameter)

  /// `preset` first: once the loader has set it, the plant fields are reset to that preset and
  /// the loader then applies the overrides written in the config.
  /// Every field is load time only (a runtime write is refused).
  void visit(edm::rt::ParamVisitor& v);
  /// Rules a range cannot say: a known preset, then the plant's cross-field rules.
  [[nodiscard]] std::vector<edm::rt::ParamError> validate() const;
};

class SimDriver final : public edm::rt::BlockWithParams<SimDriverParams, edm::rt::IoDriver> {
 public:
  std::vector<edm::rt::ParamError> configure(const edm::rt::BlockSetup& setup) override;
  void activate() noexcept override;
  void visit_pins(edm::rt::PinVisitor& v) override;
  void read_inputs(const edm::rt::CycleContext& ctx) noexcept override;
  void write_outputs(const edm::rt::CycleContext& ctx) noexcept override;
  void enter_safe_state(const edm::rt::SafeStateRequest& request) noexcept override;
  [[nodiscard]] edm::rt::IoFault fault() const noexcept override;
  bool set_seed(std::uint64_t seed) override;
  /// `electrode_length_mm` reads the plant's length left, `hole_depth_mm`, `hole_x_mm`,
  /// `hole_y_mm` its hole (what a retain store saves); every other parameter reads its accepted
  /// value. Non-RT (any thread: the live values are atomics).
  [[nodiscard]] edm::rt::ParamValue read_param(std::size_t index) const override;
  /// Notes which parameter a runtime write changes, for params_changed(). RT-safe.
  void apply_param(std::size_t index, const edm::rt::ParamValue& v) noexcept override;

  /// The plant (tests and benchmarks). Valid after configure().
  [[nodiscard]] Plant& plant() noexcept { return *plant_; }

 protected:
  /// A write of `electrode_length_mm` sets the plant's length left; of `hole_depth_mm`,
  /// `hole_x_mm` or `hole_y_mm` that one figure of the plant's hole. RT-safe.
  void params_changed() noexcept override;

 private:
  void publish_live() noexcept;

  std::unique_ptr<Plant> plant_;
  // The runtime-writable parameters' indices (visit order) and their live values, published
  // for read_param on other threads.
  enum Live : std::size_t { kElectrode, kHoleDepth, kHoleX, kHoleY, kLiveCount };
  std::size_t live_index_[kLiveCount]{};
  std::atomic<double> live_[kLiveCount]{};
  std::size_t changed_param_{static_cast<std::size_t>(-1)};
  bool started_{false};
  edm::rt::TimePoint origin_{};  // clock time of the first latch = plant time 0

  // Plant-state fields published as they are: one row names the pin and the field (sim_driver.cpp).
  struct StateOutput;
  static const StateOutput kAxisOutputs[6];
  static const StateOutput kTruthOutputs[4];

  // Inputs to the runtime (the driver's outputs).
  edm::rt::Output<std::int64_t> td_sum_ns_, td_count_;
  edm::rt::Output<std::int64_t> n_[5];
  edm::rt::Output<double> ratio_[5];
  edm::rt::Output<std::int64_t> hist_open_, hist_short_, hist_arc_;
  edm::rt::Output<double> rab_, gap_voltage_v_, x_mm_, y_mm_, z_mm_;
  edm::rt::Output<double> electrode_mm_, depth_mm_, wall_radius_mm_, true_gap_um_, true_debris_;
  edm::rt::Output<double> true_kerf_debris_, wire_load_;
  edm::rt::Output<bool> wire_broken_, driver_fault_;
  edm::rt::Output<bool> ref_[3], contact_;
  edm::rt::Output<double> hole_work_x_mm_, hole_work_y_mm_;
  // Outputs from the runtime.
  edm::rt::Input<double> vx_cmd_, vy_cmd_, vz_cmd_;
  edm::rt::Input<bool> gen_arm_, gen_on_, polarity_positive_;
  edm::rt::Input<double> on_time_us_, off_time_us_, arc_off_time_us_, servo_ref_v_;
  edm::rt::Input<bool> flushing_on_{true};
  edm::rt::Input<double> flushing_strength_{1.0};
  edm::rt::Input<bool> rotation_on_;
  edm::rt::Input<bool> touch_mode_;
  edm::rt::Input<bool> pos_set_[3];
  edm::rt::Input<double> pos_value_mm_[3];
  bool pos_set_before_[3]{};  // for the rising edge
};

/// Registers "sim". Non-RT.
void register_sim_driver(edm::rt::DriverRegistry& r);

}  // namespace edm::sim
