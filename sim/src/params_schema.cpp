#include "edm/sim/params.hpp"

// The simulator's parameter schema, the parts of SimParams::visit (params.cpp) in the struct's
// order: every field's name, unit, description and range, declared once.

namespace edm::sim {

namespace rt = edm::rt;

void SimParams::visit_generator(rt::ParamVisitor& v) {
  v.param("open_voltage_v", open_voltage_v, {"V", "open-circuit voltage U0", rt::kPositive});
  v.param("discharge_voltage_v", discharge_voltage_v,
          {"V", "discharge voltage U_d", rt::kPositive});
  v.param("arc_voltage_v", arc_voltage_v, {"V", "arc voltage U_arc", rt::kNonNegative});
  v.param("short_voltage_v", short_voltage_v,
          {"V", "short-circuit voltage U_sh", rt::kNonNegative});
  v.param("peak_current_a", peak_current_a, {"A", "peak current Ip", rt::kPositive});
  v.param("default_on_time_us", default_on_time_us, {"us", "default on time t_on", rt::kPositive});
  v.param("default_off_time_us", default_off_time_us,
          {"us", "default off time t_off", rt::kPositive});
  v.param("default_arc_off_time_us", default_arc_off_time_us,
          {"us", "default off time after abnormal pulses", rt::kPositive});
  v.param("wait_time_us", wait_time_us,
          {"us", "T_wait: no ignition by then means an open pulse", rt::kPositive});
}

void SimParams::visit_ignition(rt::ParamVisitor& v) {
  v.param("td_law", td_law, {"", "ignition-delay median law: exp | quadratic"});
  v.param("td_gap_ref_um", td_gap_ref_um, {"um", "exp law: reference gap g_r"});
  v.param("td_tau_ref_us", td_tau_ref_us, {"us", "exp law: median at g_r, tau_r", rt::kPositive});
  v.param("td_len_um", td_len_um, {"um", "exp law: gap per e-fold l_g", rt::kPositive});
  v.param("td_tau_min_us", td_tau_min_us, {"us", "exp law: floor tau_min", rt::kNonNegative});
  v.param("td_quad_a_us", td_quad_a_us, {"us/um2", "quadratic law: a in a g^2 + b g + c"});
  v.param("td_quad_b_us", td_quad_b_us, {"us/um", "quadratic law: b"});
  v.param("td_quad_c_us", td_quad_c_us, {"us", "quadratic law: c"});
  v.param("td_quad_max_gap_um", td_quad_max_gap_um,
          {"um", "quadratic law: no ignition beyond", rt::kPositive});
  v.param("weibull_k", weibull_k, {"1", "Weibull shape of Td (1 = exponential)", rt::kPositive});
  v.param("td_debris_k", td_debris_k,
          {"1", "k_cd: median scales with exp(-k_cd c)", rt::kNonNegative});
  v.param("arc_td_max_us", arc_td_max_us,
          {"us", "arc ignition delay is uniform in [0, this)", rt::kNonNegative});
}

void SimParams::visit_shorts(rt::ParamVisitor& v) {
  v.param("short_gap_um", short_gap_um,
          {"um", "g_c: hard short at or below this gap", rt::kNonNegative});
  v.param("debris_c0", debris_c0, {"1", "debris-short threshold c0", rt::closed(0.0, 1.0)});
  v.param("debris_a_g_per_um", debris_a_g_per_um,
          {"1/um", "debris-short threshold slope a_g", rt::kNonNegative});
  v.param("debris_c_max", debris_c_max,
          {"1", "debris-short threshold cap c_max", rt::closed(0.0, 1.0)});
  v.param("debris_k_s", debris_k_s, {"1", "debris-short sigmoid steepness k_s", rt::kNonNegative});
  v.param("debris_short_us", debris_short_us,
          {"us", "t_bs: duration of a debris short", rt::kPositive});
  v.param(
      "short_events", short_events,
      {"",
       "debris bridges and tube vibration contacts (false: the model before edm-sim-params/7)"});
  v.param("bridge_rate_hz", bridge_rate_hz,
          {"1/s", "lambda_b0: bridges per second at c = c_b at the surface", rt::kNonNegative});
  v.param("bridge_debris_ref", bridge_debris_ref,
          {"1", "c_b: reference debris of the bridge hazard", rt::open_closed(0.0, 1.0)});
  v.param("bridge_debris_exp", bridge_debris_exp,
          {"1", "n_b: bridge hazard grows as (c/c_b)^n_b", rt::kNonNegative});
  v.param("bridge_depth_mm", bridge_depth_mm,
          {"mm", "h_b: bridge hazard grows as 1 + h/h_b", rt::kPositive});
  v.param("bridge_mean_ms", bridge_mean_ms,
          {"ms", "t_b: mean life of a debris bridge", rt::kPositive});
  v.param("bridge_clear_um", bridge_clear_um,
          {"um", "a back-off of the tip this large breaks a bridge", rt::kPositive});
  v.param("tube_guide_mm", tube_guide_mm,
          {"mm", "tube: free length between the guide and the surface", rt::kNonNegative});
  v.param("vib_amp_ref_um", vib_amp_ref_um,
          {"um", "tube: RMS lateral tip deflection at the free length L_ref (0: none)",
           rt::kNonNegative});
  v.param("vib_len_ref_mm", vib_len_ref_mm,
          {"mm", "tube: reference free length L_ref", rt::kPositive});
  v.param("vib_amp_exp", vib_amp_exp,
          {"1", "tube: deflection grows as (L/L_ref)^this", rt::kNonNegative});
  v.param("vib_freq_ref_hz", vib_freq_ref_hz,
          {"Hz", "tube: first bending frequency at L_ref (scales as (L_ref/L)^2)", rt::kPositive});
  v.param("contact_at_depth_mm", contact_at_depth_mm,
          {"mm", "injection: a hard contact meets the tip at this hole depth (<= 0: off)"});
  v.param("contact_clear_um", contact_clear_um,
          {"um", "injection: the tip backed off this far from the contact is clear of it",
           rt::kPositive});
  v.param("contact_persistent", contact_persistent,
          {"", "injection: the contact stays (every re-approach meets it again)"});
}

void SimParams::visit_arcs(rt::ParamVisitor& v) {
  v.param("arc_p0", arc_p0, {"1", "arc probability floor p_a0", rt::closed(0.0, 1.0)});
  v.param("arc_k_t", arc_k_t, {"1", "arc weight of a not-deionised channel k_t", rt::kNonNegative});
  v.param("deion_us", deion_us, {"us", "deionisation time tau_di", rt::kPositive});
  v.param("arc_k_c", arc_k_c, {"1", "arc weight of debris k_c", rt::kNonNegative});
  v.param("arc_k_g", arc_k_g, {"1", "arc weight of a small gap k_g", rt::kNonNegative});
  v.param("arc_gap_um", arc_gap_um, {"um", "arc gap scale g_a", rt::kPositive});
  v.param("arc_p_max", arc_p_max, {"1", "arc probability cap", rt::closed(0.0, 1.0)});
}

void SimParams::visit_removal(rt::ParamVisitor& v) {
  v.param("removal_mm3_per_j", removal_mm3_per_j,
          {"mm3/J", "eta: removal per discharge energy (0: crater law)", rt::kNonNegative});
  v.param("crater_ref_um3", crater_ref_um3,
          {"um3", "crater volume at 1 A (crater law; 0: removal_mm3_per_j)", rt::kNonNegative});
  v.param("crater_exp", crater_exp, {"1", "crater law exponent on Ip", rt::kNonNegative});
  v.param("removal_sigma", removal_sigma,
          {"1", "sigma_v: relative crater scatter", rt::kNonNegative});
  v.param("arc_removal_ratio", arc_removal_ratio,
          {"1", "alpha_arc: arc removal / spark removal", rt::kNonNegative});
  v.param("arc_wear_factor", arc_wear_factor,
          {"1", "wear ratio multiplier for arcs", rt::kNonNegative});
  v.param("wear_ratio", wear_ratio,
          {"1", "theta: electrode/work volume, negative polarity", rt::kNonNegative});
  v.param("wear_ratio_positive", wear_ratio_positive,
          {"1", "theta for positive polarity", rt::kNonNegative});
  v.param("removal_scale_positive", removal_scale_positive,
          {"1", "removal x this, positive pol.", rt::kNonNegative});
}

void SimParams::visit_electrode(rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("tool_kind", tool_kind, {"", "tube | block | wire"});
  v.param("tool_od_mm", tool_od_mm, {"mm", "tube outer diameter"});
  v.param("tool_id_mm", tool_id_mm, {"mm", "tube inner diameter"});
  v.param("hole_d_mm", hole_d_mm, {"mm", "tube: initial hole diameter"});
  v.param("side_gap_mm", side_gap_mm, {"mm", "block: side gap per side"});
  v.param("tool_width_mm", tool_width_mm, {"mm", "block width"});
  v.param("tool_length_mm", tool_length_mm, {"mm", "block length"});
  v.param("wire_d_mm", wire_d_mm, {"mm", "wire diameter D"});
  // Through `writable`, runtime-writable: the retained electrode length is restored through this
  // (§5a). Its range: 100 km, the wire on a spool (20 kg of Ø0.25 mm brass is ~48 km; the wire
  // preset has 1 km); the hole's below: 5 m, beyond any EDM machine's travel.
  writable.param("electrode_length_mm", electrode_length_mm,
                 {"mm", "electrode length; reads the length left, a runtime write sets it",
                  rt::closed(0.0, 1.0e8)});
  v.param("work_thickness_mm", work_thickness_mm,
          {"mm", "through at this depth (0: blind)", rt::kNonNegative});
  v.param("start_gap_um", start_gap_um,
          {"um", "tip above the work surface at start", rt::kNonNegative});
  v.param("initial_depth_mm", initial_depth_mm,
          {"mm",
           "tube/block: a hole this deep is already there under the electrode; the tip starts "
           "start_gap_um above its bottom",
           rt::kNonNegative});
}

void SimParams::visit_work(rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("work_surface_z_mm", work_surface_z_mm, {"mm", "machine Z of the work's top surface"});
  v.param("work_origin_x_mm", work_origin_x_mm, {"mm", "machine X of the work's datum"});
  v.param("work_origin_y_mm", work_origin_y_mm, {"mm", "machine Y of the work's datum"});
  v.param("work_x_min_mm", work_x_min_mm, {"mm", "work block: lowest X, relative to the datum"});
  v.param("work_x_max_mm", work_x_max_mm,
          {"mm", "work block: highest X, relative to the datum (> min)"});
  v.param("work_y_min_mm", work_y_min_mm, {"mm", "work block: lowest Y, relative to the datum"});
  v.param("work_y_max_mm", work_y_max_mm,
          {"mm", "work block: highest Y, relative to the datum (> min)"});
  v.param("work_bore_x_mm", work_bore_x_mm, {"mm", "through bore: centre X relative to the datum"});
  v.param("work_bore_y_mm", work_bore_y_mm, {"mm", "through bore: centre Y relative to the datum"});
  v.param("work_bore_d_mm", work_bore_d_mm,
          {"mm", "through bore diameter, inside the block (0: none)", rt::kNonNegative});
  v.param("start_x_mm", start_x_mm, {"mm", "machine X of the electrode at power-on"});
  v.param("start_y_mm", start_y_mm, {"mm", "machine Y of the electrode at power-on"});
  v.param("ref_x_mm", ref_x_mm, {"mm", "X reference switch: on at or beyond this machine X"});
  v.param("ref_y_mm", ref_y_mm, {"mm", "Y reference switch: on at or beyond this machine Y"});
  v.param("ref_z_mm", ref_z_mm, {"mm", "Z reference switch: on at or beyond this machine Z"});
  v.param(
      "ref_repeat_um", ref_repeat_um,
      {"um", "reference switches: SD of the trip point, drawn anew per trip", rt::kNonNegative});
  v.param("ref_hysteresis_um", ref_hysteresis_um,
          {"um", "reference switches: release this far below the trip point", rt::kNonNegative});
  v.param("encoder_offset_x_mm", encoder_offset_x_mm,
          {"mm", "X encoder reads machine X - this at power-on"});
  v.param("encoder_offset_y_mm", encoder_offset_y_mm,
          {"mm", "Y encoder reads machine Y - this at power-on"});
  v.param("encoder_offset_z_mm", encoder_offset_z_mm,
          {"mm", "Z encoder reads machine Z - this at power-on"});
  v.param(
      "touch_gap_um", touch_gap_um,
      {"um", "touch mode: contact within this distance of the work's material", rt::kNonNegative});
  v.param("touch_noise_um", touch_noise_um,
          {"um", "touch mode: SD of that distance, drawn anew per contact", rt::kNonNegative});
  v.param("touch_voltage_v", touch_voltage_v,
          {"V", "touch mode: gap voltage while open (0 V in contact)", rt::kNonNegative});
  // Through `writable`, runtime-writable: a retain store restores the hole through these
  // (docs/simulator.md §5a).
  writable.param("hole_depth_mm", hole_depth_mm,
                 {"mm", "the hole in the work: reads its live depth, a write sets it",
                  rt::closed(0.0, 5000.0)});
  writable.param("hole_x_mm", hole_x_mm,
                 {"mm", "the hole's axis, machine X: reads the live one, a write sets it",
                  rt::closed(-5000.0, 5000.0)});
  writable.param("hole_y_mm", hole_y_mm,
                 {"mm", "the hole's axis, machine Y: reads the live one, a write sets it",
                  rt::closed(-5000.0, 5000.0)});
}

void SimParams::visit_flushing(rt::ParamVisitor& v) {
  v.param("debris_kappa", debris_kappa, {"1", "kappa: c += kappa V / V_gap", rt::kNonNegative});
  v.param("debris_flush_k", debris_flush_k,
          {"1", "k in the flushing term exp(-k c)", rt::kNonNegative});
  v.param("flush_tau0_ms", flush_tau0_ms,
          {"ms", "tau_f0: flushing time constant at the surface", rt::kPositive});
  v.param("flush_depth_mm", flush_depth_mm,
          {"mm", "h_f: tau_f = tau_f0 (1 + (h/h_f)^2)", rt::kPositive});
  v.param("flush_gap_ref_um", flush_gap_ref_um,
          {"um", "g_ref: flushing x min(1, (g/g_ref)^3)", rt::kPositive});
  v.param("flush_factor", flush_factor, {"1", "F: scenario flushing factor", rt::closed(0.0, 1.0)});
  v.param("flush_drop_depth_mm", flush_drop_depth_mm,
          {"mm", "scenario: F drops beyond depth", rt::kNonNegative});
  v.param("flush_drop_factor", flush_drop_factor,
          {"1", "scenario: F x this beyond that depth", rt::kNonNegative});
  v.param("near_tip_zone_mm", near_tip_zone_mm,
          {"mm", "l_z: side zone near the tip", rt::kPositive});
  v.param("jump_dz_mm", jump_dz_mm, {"mm", "a retract longer than this is a jump", rt::kPositive});
  v.param("jump_eps", jump_eps,
          {"1", "a jump multiplies c by (1 - jump_eps)", rt::closed(0.0, 1.0)});
  v.param("wall_sparks", wall_sparks, {"", "tube: wall bins compete with the front (orbit)"});
}

void SimParams::visit_axes(rt::ParamVisitor& v) {
  v.param("axis_wn_rad_s", axis_wn_rad_s,
          {"rad/s", "position loop natural frequency", rt::kPositive});
  v.param("axis_zeta", axis_zeta, {"1", "position loop damping", rt::kPositive});
  v.param("v_max_mm_s", v_max_mm_s,
          {"mm/s", "feed speed limit (toward the work, x, y)", rt::kPositive});
  v.param("v_jump_mm_s", v_jump_mm_s,
          {"mm/s", "retract speed limit (z away from the work)", rt::kPositive});
  v.param("a_max_mm_s2", a_max_mm_s2, {"mm/s2", "acceleration limit", rt::kPositive});
  v.param("encoder_um", encoder_um,
          {"um", "encoder quantum of reported positions", rt::kNonNegative});
  v.param("servo_gain_mm_s_per_v", servo_gain_mm_s_per_v,
          {"mm/s/V",
           "machine servo gain k: vz += -k (U_av - servo_ref_v) while servo_ref_v > 0 (0: none)",
           rt::kNonNegative});
  v.param("axis_step_us", axis_step_us, {"us", "axis integration sub-step", rt::closed(1.0, 50.0)});
}

void SimParams::visit_wire(rt::ParamVisitor& v) {
  v.param("wire_thickness_profile", wire_thickness_profile, {"mm:mm", "cut length:thickness,..."});
  v.param("wire_hole_from_mm", wire_hole_from_mm,
          {"mm", "internal hole starts at this length", rt::kNonNegative});
  v.param("wire_hole_to_mm", wire_hole_to_mm, {"mm", "internal hole ends at this length"});
  v.param("wire_ibk_ref_a", wire_ibk_ref_a,
          {"A", "break current I_BK at H = 10 mm, f = 1", rt::kPositive});
  v.param("wire_flush_floor", wire_flush_floor,
          {"1", "f = floor + (1 - floor) F_eff", rt::closed(0.0, 1.0)});
  v.param("wire_break_current_ms", wire_break_current_ms,
          {"ms", "break after mean I > I_BK this", rt::kPositive});
  v.param("wire_break_rab", wire_break_rab,
          {"1", "rupture hazard: at this Rab ...", rt::closed(0.0, 1.0)});
  v.param("wire_break_rab_ms", wire_break_rab_ms,
          {"ms", "... the mean time to break is this", rt::kPositive});
  v.param("wire_break_rab_width", wire_break_rab_width,
          {"1", "hazard x e per this Rab above", rt::kPositive});
  v.param("wire_break_rab_tau_ms", wire_break_rab_tau_ms,
          {"ms", "hazard acts on Rab lagged by", rt::kPositive});
  v.param("wire_break_rab_shape", wire_break_rab_shape,
          {"1", "k: tolerated damage ~ Gamma(k, 1/k), a whole number",
           rt::closed(1.0, static_cast<double>(kMaxWireBreakShape))});
  v.param("wire_kerf_debris_per_mm", wire_kerf_debris_per_mm,
          {"1/mm", "kerf debris c_k added per mm of cut (0 = no kerf debris)", rt::kNonNegative});
  v.param("wire_kerf_flush_s", wire_kerf_flush_s,
          {"s", "tau_k of the kerf debris at H = 10 mm", rt::kPositive});
  v.param("wire_kerf_flush_exp", wire_kerf_flush_exp,
          {"1", "tau_k grows as (H/10 mm)^this", rt::kNonNegative});
  v.param("wire_nozzle_radius_mm", wire_nozzle_radius_mm,
          {"mm", "flushing nozzle radius", rt::kNonNegative});
  v.param("wire_hole_flush_factor", wire_hole_flush_factor,
          {"1", "F_eff x this while the nozzle overlaps the internal hole", rt::closed(0.0, 1.0)});
  v.param("wire_cavity_from_mm", wire_cavity_from_mm,
          {"mm", "internal cavity starts at this length", rt::kNonNegative});
  v.param("wire_cavity_to_mm", wire_cavity_to_mm, {"mm", "internal cavity ends (far wall) here"});
  v.param("wire_cavity_height_mm", wire_cavity_height_mm,
          {"mm", "void height of the cavity, centred in H, < H over the cavity", rt::kNonNegative});
  v.param("wire_cavity_flush_factor", wire_cavity_flush_factor,
          {"1", "flush of the wire's centre part at the cavity's far wall", rt::closed(0.0, 1.0)});
  v.param(
      "wire_cavity_flush_mm", wire_cavity_flush_mm,
      {"mm", "that flush loss fades e-fold per this much cut past the far wall", rt::kPositive});
  v.param("wire_cavity_debris", wire_cavity_debris,
          {"1", "debris of the cavity's stagnant dielectric, met at the far wall",
           rt::closed(0.0, 1.0)});
  v.param("mean_current_ema_ms", mean_current_ema_ms,
          {"ms", "time constant of mean current", rt::kPositive});
  v.param("wire_plane", wire_plane, {"", "2-D cut: the wire's XY from the axes, the plate eroded"});
  v.param("wire_plate_mm", wire_plate_mm, {"mm", "2-D: plate thickness", rt::kPositive});
  v.param("wire_plate_x_min_mm", wire_plate_x_min_mm, {"mm", "2-D: plate extent, machine X min"});
  v.param("wire_plate_x_max_mm", wire_plate_x_max_mm, {"mm", "2-D: plate extent, machine X max"});
  v.param("wire_plate_y_min_mm", wire_plate_y_min_mm, {"mm", "2-D: plate extent, machine Y min"});
  v.param("wire_plate_y_max_mm", wire_plate_y_max_mm, {"mm", "2-D: plate extent, machine Y max"});
  v.param("wire_grid_um", wire_grid_um,
          {"um", "2-D: material field pitch", rt::closed(1.0, 100.0)});
  v.param("wire_start_hole_x_mm", wire_start_hole_x_mm, {"mm", "2-D: start hole centre X"});
  v.param("wire_start_hole_y_mm", wire_start_hole_y_mm, {"mm", "2-D: start hole centre Y"});
  v.param("wire_start_hole_d_mm", wire_start_hole_d_mm,
          {"mm", "2-D: start hole diameter (0: none)", rt::kNonNegative});
  v.param("wire_step_x_mm", wire_step_x_mm, {"mm", "2-D: thickness step at this machine X"});
  v.param("wire_step_mm", wire_step_mm, {"mm", "2-D: thickness added for x >= step_x"});
  v.param("wire_void_x_mm", wire_void_x_mm, {"mm", "2-D: internal void centre X"});
  v.param("wire_void_y_mm", wire_void_y_mm, {"mm", "2-D: internal void centre Y"});
  v.param("wire_void_d_mm", wire_void_d_mm,
          {"mm", "2-D: internal void diameter (0: none)", rt::kNonNegative});
  v.param("wire_void_height_mm", wire_void_height_mm,
          {"mm", "2-D: internal void height, centred in the thickness", rt::kNonNegative});
  v.param("wire_reach_um", wire_reach_um,
          {"um", "2-D: discharges reach material this far from the wire", rt::kPositive});
  v.param("wire_erode_ms", wire_erode_ms,
          {"ms", "2-D: the field takes the removal this often", rt::closed(0.025, 100.0)});
}

void SimParams::visit_sensors(rt::ParamVisitor& v) {
  v.param("rab_window_ms", rab_window_ms, {"ms", "Rab window", rt::kPositive});
  v.param("mean_voltage_tau_ms", mean_voltage_tau_ms,
          {"ms", "U_av filter time constant", rt::kPositive});
  v.param("td_quantum_ns", td_quantum_ns, {"ns", "Td quantisation (FPGA)", rt::at_least(1.0)});
  v.param("max_pulses_per_advance", max_pulses_per_advance,
          {"1", "pulse budget per advance_to", rt::at_least(1.0)});
}

}  // namespace edm::sim
