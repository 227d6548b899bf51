#pragma once
// Parameters of the plant simulator: one flat struct holding every number of PLANT-MODEL.md §6.5,
// with its unit in its name. The member defaults are the DRILL preset; preset() gives the others.
// docs/simulator.md lists each one with its source ([src] or [bk]).
//
// RT-safety: none of this is RT (strings, vectors); the Plant resolves the struct once at
// construction. Thread-safety: plain value type; preset() and preset_names() are pure.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/param.hpp"

namespace edm::sim {

/// Version of the parameter set (names, meanings, defaults). Logged with every run (§6.6);
/// bump it when a name, a unit, a default or the meaning of a parameter changes.
inline constexpr std::string_view kSimParamsVersion = "edm-sim-params/8";

struct SimParams {
  // --- Generator (§1, §6.5) ---
  double open_voltage_v{100.0};          // U0
  double discharge_voltage_v{25.0};      // U_d
  double arc_voltage_v{15.0};            // U_arc
  double short_voltage_v{3.0};           // U_sh
  double peak_current_a{15.0};           // Ip
  double default_on_time_us{20.0};       // t_on (a command of 0 means this)
  double default_off_time_us{10.0};      // t_off (a command of 0 means this)
  double default_arc_off_time_us{10.0};  // t_off_arc after an abnormal pulse (command 0 means this)
  double wait_time_us{100.0};            // T_wait: no ignition by then -> open pulse

  // --- Ignition delay (§1, §6.2 step 4) ---
  std::string td_law{"exp"};   // "exp" (sink/drill) or "quadratic" (SPARC WEDM fit)
  double td_gap_ref_um{20.0};  // g_r
  double td_tau_ref_us{5.0};   // τ_r
  double td_len_um{7.0};       // ℓ_g, gap per e-fold of the median
  double td_tau_min_us{0.5};   // τ_min
  double td_quad_a_us{0.48};   // quadratic law: τ = a g² + b g + c (g in µm)
  double td_quad_b_us{-3.69};
  double td_quad_c_us{14.05};
  double td_quad_max_gap_um{25.0};  // quadratic law: no ignition beyond this gap
  double weibull_k{1.0};            // k_W (1 = exponential, SPARC)
  double td_debris_k{2.0};          // k_cd: debris shortens Td by e^(-k_cd c)
  double arc_td_max_us{0.5};        // arc delay ~ U(0, this)

  // --- Shorts (§6.2 steps 1-2, SPARC) ---
  double short_gap_um{2.0};  // g_c: hard short at or below
  double debris_c0{0.3};     // c_crit = min(c_max, c0 + a_g g)
  double debris_a_g_per_um{0.02};
  double debris_c_max{0.95};
  double debris_k_s{500.0};      // sigmoid steepness
  double debris_short_us{50.0};  // t_bs, duration of a debris short

  // --- Short events at the servo's gap (docs/simulator.md §4a; edm-sim-params/7) ---
  // Debris bridges: a bridge forms at the hazard λ_b = bridge_rate_hz (c/c_b)^n_b (1 + h/h_b)
  // while the electrode is in the working gap; every pulse of it is a debris short until it
  // breaks after Exp(bridge_mean_ms) or the tip backs off bridge_clear_um from where it formed.
  // Tube vibration: the tip's lateral deflection δ ~ N(0, σ(L)²), σ = vib_amp_ref_um
  // (L/vib_len_ref_mm)^vib_amp_exp, L = tube_guide_mm + the tip's depth below the surface,
  // touches the wall when |δ| > the side gap: contacts arrive at Rice's up-crossing rate
  // 2 f1 e^(−u²/2), u = side gap/σ, f1 = vib_freq_ref_hz (L_ref/L)², each a hard short.
  bool short_events{true};        // false: neither (the model before edm-sim-params/7, exactly)
  double bridge_rate_hz{12.0};    // λ_b0, bridges/s at c = c_b at the surface [bk, cal]
  double bridge_debris_ref{0.4};  // c_b
  double bridge_debris_exp{2.0};  // n_b: two-body (particle meets particle)
  double bridge_depth_mm{10.0};   // h_b: the side gap adds a front's worth per h_b of depth
  double bridge_mean_ms{1.0};     // t_b, mean life of a bridge
  double bridge_clear_um{10.0};   // a back-off this large shears a bridge
  double tube_guide_mm{5.0};      // free tube between the guide and the work surface [bk]
  double vib_amp_ref_um{20.0};    // σ at vib_len_ref_mm [bk, cal]
  double vib_len_ref_mm{50.0};    // L_ref
  double vib_amp_exp{1.5};        // σ ∝ L^this
  double vib_freq_ref_hz{200.0};  // f1 of the free length at L_ref (brass Ø1.0/0.3 tube)

  // --- Injected contact (scenarios, tests; off by default) ---
  // When the hole reaches contact_at_depth_mm (> 0), a hard contact (a chip) meets the tip:
  // every pulse is a short while the tip is less than contact_clear_um above where it met it.
  // Not persistent: the first back-off by contact_clear_um clears it for good. Persistent: the
  // chip stays there; every re-approach within contact_clear_um meets it again.
  double contact_at_depth_mm{0.0};  // <= 0: off
  double contact_clear_um{50.0};
  bool contact_persistent{false};

  // --- Arcs (§6.2 step 3) ---
  double arc_p0{0.01};
  double arc_k_t{0.3};     // weight of the not-yet-deionised channel
  double deion_us{6.0};    // τ_di
  double arc_k_c{0.3};     // weight of debris
  double arc_k_g{0.3};     // weight of a small gap
  double arc_gap_um{5.0};  // g_a
  double arc_p_max{0.9};

  // --- Removal and wear (§2, §6.2 step 6) ---
  double removal_mm3_per_j{3.2e-3};    // η (Kalpakjian), used when crater_ref_um3 == 0
  double crater_ref_um3{0.0};          // >0: crater table law V = crater_ref (Ip/1 A)^crater_exp
  double crater_exp{1.167};            // fit of SPARC's 2.2e3 µm³ @ 1 A .. 6e4 µm³ @ 17 A
  double removal_sigma{0.2};           // σ_v, relative scatter of crater volume
  double arc_removal_ratio{0.3};       // α_arc
  double arc_wear_factor{2.0};         // arcs wear the electrode this many times more per volume
  double wear_ratio{0.6};              // θ, electrode/workpiece volume, negative polarity
  double wear_ratio_positive{0.05};    // θ for positive polarity [bk]
  double removal_scale_positive{0.5};  // removal multiplier for positive polarity [bk]

  // --- Tool and workpiece geometry ---
  std::string tool_kind{"tube"};  // "tube" (drill), "block" (sink), "wire"
  double tool_od_mm{1.0};         // tube outer diameter
  double tool_id_mm{0.3};         // tube inner diameter
  double hole_d_mm{1.1};          // tube: initial hole diameter (wall bins start here)
  double side_gap_mm{0.07};       // block: side gap per side
  double tool_width_mm{10.0};     // block
  double tool_length_mm{10.0};    // block
  double wire_d_mm{0.25};         // wire diameter D
  // Tube/block length sticking out, consumed by wear. Writable at run time (as is the hole below):
  // a write says "the electrode now measures this" (a retained length restored at start, an
  // electrode change); the driver reads the length left back through it (docs/simulator.md §5a).
  double electrode_length_mm{300.0};
  double work_thickness_mm{0.0};  // tube/block: through at this depth; 0 = blind (no limit)
  double start_gap_um{100.0};     // tip above the work surface at start
  double initial_depth_mm{0.0};   // a hole already there (tip start_gap_um above its bottom)

  // --- The work on the machine, the machine's axes and its operator functions
  //     (docs/simulator.md §3a; edm-sim-params/8). The defaults are the plant before them. ---
  // Where the work is, in machine coordinates; the part program does not know it.
  double work_surface_z_mm{0.0};  // machine Z of the work's top surface
  double work_origin_x_mm{0.0};   // machine XY of the work's datum
  double work_origin_y_mm{0.0};
  double work_x_min_mm{-50.0};  // the work block's extent relative to its datum (min < max)
  double work_x_max_mm{50.0};
  double work_y_min_mm{-50.0};
  double work_y_max_mm{50.0};
  double work_bore_x_mm{0.0};  // a through bore, centre relative to the datum ...
  double work_bore_y_mm{0.0};
  double work_bore_d_mm{0.0};  // ... of this diameter (0: none); inside the block
  double start_x_mm{0.0};      // machine XY of the electrode at power-on
  double start_y_mm{0.0};
  // Reference (home) cam switches, machine coordinates: on while the axis is at or beyond the
  // trip point in +. Each trip point is drawn anew ~ N(ref, ref_repeat_um) for every trip; a
  // switch releases ref_hysteresis_um below the point it tripped at.
  double ref_x_mm{90.0};
  double ref_y_mm{90.0};
  double ref_z_mm{15.0};
  double ref_repeat_um{0.5};
  double ref_hysteresis_um{20.0};
  // Incremental encoders: at power-on an axis reads machine − offset (0: absolute encoders).
  double encoder_offset_x_mm{0.0};
  double encoder_offset_y_mm{0.0};
  double encoder_offset_z_mm{0.0};
  // Touch mode: contact when the electrode is within a threshold of the work's material, the
  // threshold ~ N(touch_gap_um, touch_noise_um) drawn anew for every contact event; the gap
  // reads touch_voltage_v while open, 0 V in contact.
  double touch_gap_um{1.0};
  double touch_noise_um{0.3};
  double touch_voltage_v{10.0};
  // The hole in the work (runtime-writable, for a retain store, like electrode_length_mm): read,
  // the live depth of the current hole below the surface and its axis in machine XY; a write sets
  // the hole already in the work (depth > 0: drilling at that XY continues it).
  double hole_depth_mm{0.0};
  double hole_x_mm{0.0};
  double hole_y_mm{0.0};

  // --- Debris and flushing (§6.2 step 7) ---
  double debris_kappa{0.75};        // κ: c += κ V / V_gap; calibrated [bk], see simulator.md
  double debris_flush_k{1.0};       // k in e^(-k c) (SPARC)
  double flush_tau0_ms{5.0};        // τ_f0
  double flush_depth_mm{5.0};       // h_f: τ_f = τ_f0 (1 + (h/h_f)²); not used for wire
  double flush_gap_ref_um{25.0};    // g_ref
  double flush_factor{1.0};         // F of the scenario (0..1)
  double flush_drop_depth_mm{0.0};  // scenario: beyond this depth F is multiplied by ...
  double flush_drop_factor{1.0};    // ... this (1 = no drop)
  double near_tip_zone_mm{1.0};     // ℓ_z, side zone counted in V_gap and in wall bins
  double jump_dz_mm{1.0};           // Δz_j: a retract longer than this ...
  double jump_eps{0.0};             // ... multiplies c by (1 - ε_j); 0 = jumps do not flush
  bool wall_sparks{false};          // tube: the 64 wall bins compete with the front (orbit)

  // --- Axes (§3, §6.3) ---
  double axis_wn_rad_s{200.0};  // ω_n of the position loop
  double axis_zeta{0.55};       // ζ
  double v_max_mm_s{30.0};      // feed limit (toward the work, and x/y)
  double v_jump_mm_s{150.0};    // retract limit (away from the work)
  double a_max_mm_s2{2000.0};   // acceleration limit of the reference
  double encoder_um{0.1};       // q_z, position quantum of the reported positions
  double servo_gain_mm_s_per_v{
      0.0};                   // k of the machine's servo ε = k·(U_av − servo_ref_v); 0 = none
  double axis_step_us{25.0};  // fixed integration sub-step between pulses (<= 50)

  // --- WEDM (§6.4) ---
  std::string wire_thickness_profile{"0:10"};  // "s:H,..." cut length mm : thickness mm steps
  double wire_hole_from_mm{0.0};               // internal hole (no material) from ...
  double wire_hole_to_mm{0.0};                 // ... to this cut length; equal = none
  double wire_ibk_ref_a{3.0};                  // I_BK at H = 10 mm and f = 1 [bk]
  double wire_flush_floor{0.3};                // f = floor + (1 - floor) F_eff [bk]
  double wire_break_current_ms{5.0};           // break if Ī > I_BK this long
  double wire_break_rab{0.5};                  // abnormal-discharge rupture: at this Rab ...
  double wire_break_rab_ms{100.0};      // ... the mean time to break is this, and it falls ...
  double wire_break_rab_width{0.02};    // ... e-fold for every this much Rab above [bk]
  double wire_break_rab_tau_ms{200.0};  // the hazard acts on Rab through this lag [bk]
  // The damage ∫λ dt the wire tolerates: Gamma(k, 1/k), mean 1, CV 1/√k, drawn once per run.
  // k = 1 is Exp(1) (memoryless); a larger k is a wire of less scattered strength. Integer.
  double wire_break_rab_shape{1.0};
  // Kerf debris c_k: the debris the flushing must carry out along the kerf (height H), slow
  // against the gap's own c. Each mm of cut adds wire_kerf_debris_per_mm; it is flushed with
  // τ_k = wire_kerf_flush_s (H/10 mm)^wire_kerf_flush_exp / (F_eff min(1, (g/g_ref)³)).
  // The pulses see c + c_k. 0 = none (the §6.2 model alone). [bk, calibrated to seed 000]
  double wire_kerf_debris_per_mm{0.0};
  double wire_kerf_flush_s{1.0};
  double wire_kerf_flush_exp{1.0};
  // An internal hole under the flushing nozzle lets the flush escape: while the nozzle (this
  // radius, centred on the wire) overlaps [wire_hole_from_mm, wire_hole_to_mm), F_eff is
  // multiplied by wire_hole_flush_factor. [bk]
  double wire_nozzle_radius_mm{3.0};
  double wire_hole_flush_factor{1.0};
  // An internal cavity in the part's cross-section (seed 000's case 4, Fig. 8d): over
  // [wire_cavity_from_mm, wire_cavity_to_mm) of cut the centre wire_cavity_height_mm of the
  // thickness is void, so the cut thickness is H(s) − h_c. Past the far wall the centre part of
  // the wire is poorly flushed (the paper: "the upper and lower flushing pressure can be
  // maintained ... the centre part of wire undergoes poor flushing"): F_eff is multiplied by
  // 1 − (h_c/H)(1 − wire_cavity_flush_factor) e^(−(s − s_to)/wire_cavity_flush_mm), and as
  // the cut crosses the far wall the cavity's stagnant dielectric (debris
  // wire_cavity_debris) enters the centre part's kerf: c_k += (h_c/H) wire_cavity_debris. [bk]
  double wire_cavity_from_mm{0.0};
  double wire_cavity_to_mm{0.0};  // equal to from = none
  double wire_cavity_height_mm{0.0};
  double wire_cavity_flush_factor{1.0};
  double wire_cavity_flush_mm{1.0};
  double wire_cavity_debris{0.0};
  double mean_current_ema_ms{10.0};  // Ī time constant
  // The 2-D cut (docs/simulator.md §7b): the wire's XY comes from the axes and the plate is a
  // signed-distance field eroded by the pulses (WirePlane); Z is the upper guide's height and
  // plays no part. The 1-D profile, hole and cavity above (cut-length keyed) are not used.
  bool wire_plane{false};
  double wire_plate_mm{20.0};                                    // thickness
  double wire_plate_x_min_mm{-15.0}, wire_plate_x_max_mm{15.0};  // extent, machine XY
  double wire_plate_y_min_mm{-15.0}, wire_plate_y_max_mm{15.0};
  double wire_grid_um{10.0};  // field pitch
  double wire_start_hole_x_mm{0.0}, wire_start_hole_y_mm{0.0};
  double wire_start_hole_d_mm{0.0};               // 0: none (cut from the plate's edge)
  double wire_step_x_mm{0.0}, wire_step_mm{0.0};  // x >= step_x: thickness + step
  double wire_void_x_mm{0.0}, wire_void_y_mm{0.0};
  double wire_void_d_mm{0.0}, wire_void_height_mm{0.0};  // an internal void (0: none)
  double wire_reach_um{60.0};  // discharges reach material this far from the wire's surface
  double wire_erode_ms{2.0};   // the field takes the pulses' removal this often

  // --- Sensors (§6.2 step 8) ---
  double rab_window_ms{40.0};
  double mean_voltage_tau_ms{2.0};  // U_av filter [bk]
  std::int64_t td_quantum_ns{10};   // FPGA resolution of Td

  // --- Cost bound ---
  std::int64_t max_pulses_per_advance{100000};  // per advance_to(); beyond it pulses pause

  /// Declares every field (unit, description, range) in declaration order; all are load time
  /// only (the Plant resolves them once) but electrode_length_mm, hole_depth_mm, hole_x_mm and
  /// hole_y_mm, which the driver applies to the plant. Non-RT.
  void visit(edm::rt::ParamVisitor& v);
  /// Every problem with the values: each field against its range, then (only if all are in
  /// range) cross_field_errors(). Empty means valid. Non-RT.
  [[nodiscard]] std::vector<edm::rt::ParamError> validate() const;
  /// The rules a range cannot say: the td_law and tool_kind names, the tool's own dimensions,
  /// the WEDM profile, hole and cavity, a whole-number wire_break_rab_shape. Non-RT.
  [[nodiscard]] std::vector<edm::rt::ParamError> cross_field_errors() const;
  /// "drill", "sink" or "wire" (PLANT-MODEL.md §6.5); nullopt for another name.
  static std::optional<SimParams> preset(std::string_view name);

 private:
  // The parts of visit(), one for each section above, called in declaration order (defined in
  // params_schema.cpp). `v` marks every field it is given load time only; `writable` is visit()'s
  // own visitor, for the fields the driver applies at run time (the electrode's length, the hole).

  // The generator (§1): voltages, current, pulse times.
  void visit_generator(edm::rt::ParamVisitor& v);
  // The ignition delay (§1, §6.2 step 4).
  void visit_ignition(edm::rt::ParamVisitor& v);
  // Shorts (§6.2 steps 1-2), short events at the gap (§4a), the injected contact.
  void visit_shorts(edm::rt::ParamVisitor& v);
  // Arcs (§6.2 step 3).
  void visit_arcs(edm::rt::ParamVisitor& v);
  // Removal and wear (§2, §6.2 step 6).
  void visit_removal(edm::rt::ParamVisitor& v);
  // The tool and the work's thickness, where the tip starts.
  void visit_electrode(edm::rt::ParamVisitor& v, edm::rt::ParamVisitor& writable);
  // The work on the machine, the reference switches, encoders, touch mode, the hole (§3a).
  void visit_work(edm::rt::ParamVisitor& v, edm::rt::ParamVisitor& writable);
  // Debris and flushing (§6.2 step 7).
  void visit_flushing(edm::rt::ParamVisitor& v);
  // The axes (§3, §6.3).
  void visit_axes(edm::rt::ParamVisitor& v);
  // WEDM (§6.4).
  void visit_wire(edm::rt::ParamVisitor& v);
  // The sensors (§6.2 step 8) and the cost bound.
  void visit_sensors(edm::rt::ParamVisitor& v);
};

/// The names preset() knows, in a fixed order.
std::vector<std::string> preset_names();

/// One step of the WEDM thickness profile: from cut length from_mm on, the part is thickness_mm.
struct ThicknessStep {
  double from_mm{0.0};
  double thickness_mm{0.0};
};

/// Parses "0:10,20:60,40:10" (ascending lengths starting at 0, thicknesses > 0, at most
/// kMaxThicknessSteps steps). On error returns nullopt and says why in *error. Non-RT.
inline constexpr std::size_t kMaxThicknessSteps = 16;

/// Largest wire_break_rab_shape (the threshold sums this many Exp(1) draws at construction).
inline constexpr int kMaxWireBreakShape = 64;
std::optional<std::vector<ThicknessStep>> parse_thickness_profile(std::string_view text,
                                                                  std::string* error);

}  // namespace edm::sim
