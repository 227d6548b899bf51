#pragma once
// The EDM plant: discharge gap, generator, debris, electrode wear, axes and wire, advanced
// event by event (one event per pulse) on an int64-ns time line. PLANT-MODEL.md §6;
// docs/simulator.md is the model as built.
//
// RT-safety: advance_to(), set_commands(), take_sensors(), enter_safe_state() never allocate,
// lock or throw (the plant runs inside the I/O task's input latch). Construction is non-RT.
// Thread-safety: one thread.

#include <array>
#include <cstdint>

#include "edm/runtime/time.hpp"
#include "edm/sim/axis.hpp"
#include "edm/sim/gap_model.hpp"
#include "edm/sim/monitors.hpp"
#include "edm/sim/params.hpp"
#include "edm/sim/wire_plane.hpp"
#include "edm/sim/work_geometry.hpp"

namespace edm::sim {

// PulseClass (open, normal, transient arc, stable arc, short) is in gap_model.hpp.

/// What the runtime commands (the driver copies its input pins here each cycle).
struct PlantCommands {
  // Axis velocity commands. +z moves away from the work; for the wire, z is the position along
  // the cut and −z is forward (x and y play no part in the wire physics yet).
  double vx_mm_s{0.0}, vy_mm_s{0.0}, vz_mm_s{0.0};
  bool generator_armed{false};
  bool generator_on{false};
  bool polarity_positive{false};  // false: negative (drilling), true: positive (finishing)
  double on_time_us{0.0};         // 0: preset default
  double off_time_us{0.0};        // 0: preset default
  double arc_off_time_us{0.0};    // off time after an abnormal pulse; 0: = off_time
  // > 0: the machine's own gap-voltage servo (PLANT-MODEL §3, ε = k·(U_av − COMP)) adds
  // −servo_gain·(U_av − servo_ref_v) to vz: it advances while U_av is above the reference.
  // 0 (or servo_gain_mm_s_per_v = 0, the drill preset): no machine servo (vz alone).
  double servo_ref_v{0.0};
  bool flushing_on{true};
  double flushing_strength{1.0};  // 0..1, multiplies the scenario's flushing factor F
  bool rotation_on{false};
  // The generator's touch mode: no discharges whatever generator_on says, a low sensing voltage
  // across the gap, and contact sensing (PlantState::touch_contact).
  bool touch_mode{false};
};

/// Sensor values accumulated since the last take_sensors() (one PLC cycle), FPGA-style.
struct CycleSensors {
  std::int64_t td_sum_ns{0};       // sum of ignition delays of pulses that ignited (normal + arcs)
  std::int64_t td_count{0};        // how many
  std::int64_t count[5]{};         // pulses by PulseClass
  std::int64_t time_ns[5]{};       // time spent in each class (for five-state time ratios)
  double mean_gap_voltage_v{0.0};  // time-averaged gap voltage over the cycle
};

/// The plant's state as the sensors and the trace see it.
struct PlantState {
  edm::rt::TimePoint now{};
  // Encoder readings (quantised): machine position − encoder offset, or what a set_encoder_mm()
  // made them read. With the default parameters they are the machine coordinates.
  double x_mm{0.0}, y_mm{0.0}, z_mm{0.0};
  // True machine coordinates (not quantised; the work's surface is at work_surface_z_mm).
  double machine_x_mm{0.0}, machine_y_mm{0.0}, machine_z_mm{0.0};
  double vz_mm_s{0.0};
  double gap_um{0.0};               // front gap
  double debris{0.0};               // c in [0, 1]
  double kerf_debris{0.0};          // WEDM: c_k in [0, 1], slow debris along the kerf
  double depth_mm{0.0};             // hole depth h (drill), or cut length (wire)
  double wall_radius_mm{0.0};       // mean hole wall radius (orbit bins)
  double electrode_length_mm{0.0};  // electrode length left
  double removed_mm3{0.0};          // workpiece volume removed so far
  double wear_mm3{0.0};             // electrode volume worn so far
  std::uint32_t history_open{0}, history_short{0}, history_arc{0};  // last 32 pulses, bit 0 newest
  double rab{0.0};             // (arc + short) / total over the Rab window
  double mean_current_a{0.0};  // WEDM: EMA of Ip·t_on duty (Ī)
  double wire_load{0.0};       // WEDM: Ī / I_BK (the wire breaks after 5 ms above 1)
  bool wire_broken{false};
  std::uint64_t pulses{0};  // pulse index (keys the random variates)
  // Added by the simulator core:
  PulseClass last_class{PulseClass::kOpen};  // class of the newest pulse
  std::int64_t last_td_ns{0};                // its delay (quantised; T_wait when open)
  double gap_voltage_filtered_v{0.0};        // U_av: 1st-order filter of the gap voltage
  double flush_effective{0.0};               // F_eff = F x strength x drop (0 = off)
  std::uint64_t budget_overruns{0};          // advances that hit max_pulses_per_advance
  // Short events (docs/simulator.md §4a):
  bool contact{false};                  // the injected contact holds the gap short now
  std::uint64_t bridges{0};             // debris bridges formed so far
  std::uint64_t vibration_contacts{0};  // lateral tube contacts so far
  // The work and the operator functions (docs/simulator.md §3a):
  bool ref_x{false}, ref_y{false}, ref_z{false};  // reference switches
  bool touch_contact{false};  // touch mode and the electrode within the touch gap of material
  double hole_depth_mm{0.0};  // the hole in the work (kept while the electrode is elsewhere)
  double hole_x_mm{0.0}, hole_y_mm{0.0};            // its axis, machine XY
  double hole_work_x_mm{0.0}, hole_work_y_mm{0.0};  // its axis, relative to the work's datum
};

class Plant {
 public:
  /// Throws std::invalid_argument when params.validate() finds a problem. Non-RT.
  Plant(const SimParams& params, std::uint64_t seed);

  /// Takes effect at the current plant time (the generator starts or stops there).
  void set_commands(const PlantCommands& c) noexcept;
  /// Runs every pulse and axis step up to time t (never backwards). Cost is bounded by
  /// params().max_pulses_per_advance; beyond it the generator pauses (no pulses, 0 V) until t
  /// and state().budget_overruns counts it; axes keep integrating (O(interval / axis_step)).
  void advance_to(edm::rt::TimePoint t) noexcept;
  /// The sensors accumulated since the previous call, then resets them.
  CycleSensors take_sensors() noexcept;
  [[nodiscard]] const PlantState& state() const noexcept { return state_; }
  /// Generator off at once, axes commanded to 0.
  void enter_safe_state() noexcept;
  [[nodiscard]] const SimParams& params() const noexcept { return params_; }

  // Test hooks: hold the front gap fixed (the axis follows the hole bottom so g stays at
  // gap_um), and set the hole depth / debris directly.
  void hold_gap(double gap_um) noexcept;
  void release_gap() noexcept;
  void set_depth_mm(double h) noexcept;
  void set_debris(double c) noexcept;
  /// Every pulse that begins within `duration` from the plant's time now is a short (a hard
  /// contact for that long, whatever the gap): the safety tests' short bursts. RT-safe.
  void inject_short(edm::rt::Duration duration) noexcept;
  /// The wire breaks now (the safety tests' wire break, whatever the rupture model says): the
  /// generator stops, wire_broken holds until the wire is threaded again. RT-safe.
  void break_wire() noexcept;
  /// The wire is threaded again (an operator's rethread): wire_broken clears. RT-safe.
  void thread_wire() noexcept;
  /// The electrode now measures `mm` (a retained length restored at start, an electrode
  /// change): the wear becomes electrode_length_mm − mm, so the tip sits that much above where a
  /// new electrode's would. RT-safe.
  void set_electrode_length_mm(double mm) noexcept;
  /// A drive's "set actual position": axis 0, 1, 2 (x, y, z) reads `reading_mm` from now on;
  /// the machine does not move. RT-safe.
  void set_encoder_mm(int axis, double reading_mm) noexcept;
  /// The hole already in the work (a retained hole restored at start): its axis at machine XY
  /// (x_mm, y_mm), depth_mm below the surface; depth 0 = none yet (the next hole begins wherever
  /// the electrode erodes first). Tube and block; for the wire, depth_mm is the cut length.
  /// RT-safe.
  void set_hole_mm(double x_mm, double y_mm, double depth_mm) noexcept;

  /// The wire machine's plate in plan view (wire_plane): the truth a test measures a part on.
  /// Inactive for the other tools and the 1-D wire.
  [[nodiscard]] const WirePlane& wire_plane() const noexcept { return plane_; }

  /// Tube hole wall: radius of bin j (angle 2πj/kWallBins from +x) at the tip, mm.
  static constexpr std::size_t kWallBins = 64;
  [[nodiscard]] double wall_bin_radius_mm(std::size_t j) const noexcept { return wall_r_mm_[j]; }

 private:
  enum class Phase : std::uint8_t { kIdle, kWait, kOn, kOff };
  enum class Tool : std::uint8_t { kTube, kBlock, kWire };

  [[nodiscard]] bool generator_enabled() const noexcept;
  [[nodiscard]] double tool_z_mm(std::int64_t t_ns) const noexcept;  // axis z extrapolated
  [[nodiscard]] double front_gap_um(double z_mm) const noexcept;
  [[nodiscard]] double depth_mm() const noexcept;   // of the hole under the electrode
  [[nodiscard]] double bottom_mm() const noexcept;  // z of what is under the electrode
  [[nodiscard]] double wall_gap_um(std::size_t j) const noexcept;
  [[nodiscard]] double gap_volume_mm3(double gap_um) const noexcept;
  [[nodiscard]] double flush_effective() const noexcept;
  /// Wire: the thickness being cut here, H(s) less an internal cavity's void height.
  [[nodiscard]] double cut_thickness_mm() const noexcept;
  /// Wire: h_c / H(s), the share of the wire's length in a cavity's centre part (≤ 1).
  [[nodiscard]] double cavity_centre_fraction(double cut_mm) const noexcept;
  void account(std::int64_t until_ns) noexcept;
  void step_axes(std::int64_t t_ns) noexcept;
  /// Tube: before any erosion the hole's axis follows the electrode's XY; once the tip is
  /// back above the surface and more than a hole diameter away, a fresh hole begins there (the
  /// simulator models one hole at a time, so a row of holes can be drilled).
  void track_hole() noexcept;
  void start_pulse(std::int64_t t_ns) noexcept;
  /// What forces pulse k to be a short before the gap physics is asked (plant_short_events.cpp):
  /// the injected contact, a debris bridge or a tube contact in progress or starting now.
  enum class ShortCause : std::uint8_t { kNone, kContact, kBridge, kVibration };
  [[nodiscard]] ShortCause short_event(std::int64_t t_ns, std::uint64_t k, double gap_um,
                                       double debris) noexcept;
  /// Between pulses: a back-off clears the injected contact (unless persistent) and breaks a
  /// bridge, even while the generator is off.
  void track_short_events() noexcept;
  [[nodiscard]] double tip_z_mm() const noexcept;  // at the last axis step
  void enter_phase(Phase ph, std::int64_t t_ns, std::int64_t dur_ns) noexcept;
  void on_phase_end(std::int64_t t_ns) noexcept;
  void remove(double volume_mm3, double wear_mm3, double gap_um, int site) noexcept;
  void update_wire(std::int64_t t_ns) noexcept;
  void set_idle(std::int64_t t_ns) noexcept;
  void publish() noexcept;
  // The work and the operator functions (plant_work.cpp).
  void init_work() noexcept;
  void update_ref_switches() noexcept;
  void update_touch() noexcept;
  void set_touch_mode(bool on) noexcept;
  [[nodiscard]] double touch_distance_um() const noexcept;
  [[nodiscard]] double touch_threshold_um(std::uint64_t event) const noexcept;
  [[nodiscard]] double touch_release_um() const noexcept;
  [[nodiscard]] double idle_voltage_v() const noexcept;  // the gap's voltage with no pulse
  [[nodiscard]] double mean_wall_radius_mm() const noexcept;
  void start_fresh_hole() noexcept;

  SimParams params_;
  PlantState state_;
  GapModel model_;
  std::uint64_t seed_;
  Tool tool_{Tool::kTube};
  PlantCommands cmd_{};
  CycleSensors sensors_{};
  std::int64_t sensor_elapsed_ns_{0};
  double sensor_volt_ns_{0.0};  // ∫U dt since take_sensors, V·ns

  // Geometry (mm; +z away from the work, surface at 0, hole bottom z_w = −depth).
  double area_front_mm2_{0.0}, area_electrode_mm2_{0.0}, side_area_mm2_{0.0};
  double hole_bottom_mm_{0.0};
  double wear_length_mm_{0.0};  // electrode consumed: the tip is at z + wear_length
  std::array<double, kWallBins> wall_r_mm_{};
  std::array<double, kWallBins> wall_cos_{}, wall_sin_{};
  // The hole's axis (tube): it follows the electrode until material has been removed at the
  // front, so a hole is drilled where the program puts the electrode; see track_hole().
  double hole_cx_mm_{0.0}, hole_cy_mm_{0.0};
  bool hole_started_{false};  // material removed since the hole began
  // Tube: the electrode has left the hole (tip above the surface, more than a hole diameter
  // away): the surface is under it, the hole is kept until material is removed elsewhere.
  bool away_{false};
  ThicknessProfile profile_{};

  // Axes.
  std::array<Axis, 3> axes_{};
  std::int64_t axis_time_ns_{0}, axis_step_ns_{25'000};
  bool hold_{false};
  double hold_gap_um_{0.0};
  double jump_low_z_mm_{0.0};
  bool jump_armed_{true};

  // Generator.
  Phase phase_{Phase::kIdle};
  PulseClass cls_{PulseClass::kOpen};
  std::int64_t phase_end_ns_{0};
  std::int64_t on_ns_{0}, off_ns_{0};  // durations of the current pulse's ON and OFF phases
  double on_voltage_v_{0.0}, phase_voltage_v_{0.0};
  std::int64_t accounted_ns_{0};
  std::int64_t last_discharge_end_ns_{-1'000'000'000};
  std::int64_t pulses_this_advance_{0};
  bool paused_{false};

  // Short events: at most one bridge or tube contact at a time, and the injected contact.
  ShortCause episode_{ShortCause::kNone};
  std::int64_t episode_end_ns_{0};
  double episode_tip_mm_{0.0};  // tip z where the bridge formed
  std::int64_t last_pulse_ns_{0};
  double working_gap_um_{0.0};  // beyond it a clean gap never ignites: nothing forms there
  enum class Contact : std::uint8_t { kArmed, kMet, kCleared, kOff };
  Contact contact_{Contact::kOff};
  double contact_tip_mm_{0.0};             // tip z where the injected contact was met
  std::int64_t injected_short_end_ns_{0};  // inject_short(): pulses before this are shorts

  // The work on the machine (plant_work.cpp). Axis positions are machine X, Y and the plant's z
  // (surface at 0); machine Z = z + work_surface_z_mm. An encoder reads position − bias.
  std::array<double, 3> enc_bias_mm_{};
  std::array<double, 3> ref_pos_mm_{};   // nominal switch positions, axis frame
  std::array<double, 3> ref_trip_mm_{};  // where each switch trips next (or tripped)
  std::array<bool, 3> ref_on_{};
  std::array<std::uint64_t, 3> ref_trips_{};
  Section tool_section_{};  // the electrode's cross-section (centre set when used)
  WorkSolid work_{};        // block and bore (the hole is filled in when used)
  bool touch_contact_{false};
  std::uint64_t touch_events_{0};  // contacts ended so far: keys the next threshold
  double touch_threshold_now_um_{0.0};

  // The 2-D wire cut: the plate, and the removal it has not taken yet (it erodes every
  // wire_erode_ms, not every pulse).
  WirePlane plane_{};
  double plane_pending_mm3_{0.0};
  std::int64_t plane_erode_ns_{1'000'000};
  std::int64_t plane_eroded_at_ns_{0};

  // Sensors and WEDM.
  RabWindow rab_{};
  WireBreakMonitor wire_monitor_{};
  std::int64_t wire_time_ns_{0};
  double current_sum_a_{0.0};  // Ī
};

}  // namespace edm::sim
