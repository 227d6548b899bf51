#include "edm/sim/params.hpp"

// The simulator's parameter schema, the parts of SimParams::visit (params.cpp) in the struct's
// order: every field's name, unit, description and range, declared once.

namespace edm::sim {

namespace rt = edm::rt;

void SimParams::visit_generator(rt::ParamVisitor& v) {
  v.param("open_voltage_v", open_voltage_v,
          {.unit = "V", .description = "open-circuit voltage U0", .range = rt::kPositive});
  v.param("discharge_voltage_v", discharge_voltage_v,
          {.unit = "V", .description = "discharge voltage U_d", .range = rt::kPositive});
  v.param("arc_voltage_v", arc_voltage_v,
          {.unit = "V", .description = "arc voltage U_arc", .range = rt::kNonNegative});
  v.param("short_voltage_v", short_voltage_v,
          {.unit = "V", .description = "short-circuit voltage U_sh", .range = rt::kNonNegative});
  v.param("peak_current_a", peak_current_a,
          {.unit = "A", .description = "peak current Ip", .range = rt::kPositive});
  v.param("default_on_time_us", default_on_time_us,
          {.unit = "us", .description = "default on time t_on", .range = rt::kPositive});
  v.param("default_off_time_us", default_off_time_us,
          {.unit = "us", .description = "default off time t_off", .range = rt::kPositive});
  v.param("default_arc_off_time_us", default_arc_off_time_us,
          {.unit = "us",
           .description = "default off time after abnormal pulses",
           .range = rt::kPositive});
  v.param("wait_time_us", wait_time_us,
          {.unit = "us",
           .description = "T_wait: no ignition by then means an open pulse",
           .range = rt::kPositive});
}

void SimParams::visit_ignition(rt::ParamVisitor& v) {
  v.param("td_law", td_law,
          {.unit = "", .description = "ignition-delay median law: exp | quadratic"});
  v.param("td_gap_ref_um", td_gap_ref_um,
          {.unit = "um", .description = "exp law: reference gap g_r"});
  v.param("td_tau_ref_us", td_tau_ref_us,
          {.unit = "us", .description = "exp law: median at g_r, tau_r", .range = rt::kPositive});
  v.param("td_len_um", td_len_um,
          {.unit = "um", .description = "exp law: gap per e-fold l_g", .range = rt::kPositive});
  v.param("td_tau_min_us", td_tau_min_us,
          {.unit = "us", .description = "exp law: floor tau_min", .range = rt::kNonNegative});
  v.param("td_quad_a_us", td_quad_a_us,
          {.unit = "us/um2", .description = "quadratic law: a in a g^2 + b g + c"});
  v.param("td_quad_b_us", td_quad_b_us, {.unit = "us/um", .description = "quadratic law: b"});
  v.param("td_quad_c_us", td_quad_c_us, {.unit = "us", .description = "quadratic law: c"});
  v.param(
      "td_quad_max_gap_um", td_quad_max_gap_um,
      {.unit = "um", .description = "quadratic law: no ignition beyond", .range = rt::kPositive});
  v.param("weibull_k", weibull_k,
          {.unit = "1",
           .description = "Weibull shape of Td (1 = exponential)",
           .range = rt::kPositive});
  v.param("td_debris_k", td_debris_k,
          {.unit = "1",
           .description = "k_cd: median scales with exp(-k_cd c)",
           .range = rt::kNonNegative});
  v.param("arc_td_max_us", arc_td_max_us,
          {.unit = "us",
           .description = "arc ignition delay is uniform in [0, this)",
           .range = rt::kNonNegative});
}

void SimParams::visit_shorts(rt::ParamVisitor& v) {
  v.param("short_gap_um", short_gap_um,
          {.unit = "um",
           .description = "g_c: hard short at or below this gap",
           .range = rt::kNonNegative});
  v.param("debris_c0", debris_c0,
          {.unit = "1", .description = "debris-short threshold c0", .range = rt::closed(0.0, 1.0)});
  v.param("debris_a_g_per_um", debris_a_g_per_um,
          {.unit = "1/um",
           .description = "debris-short threshold slope a_g",
           .range = rt::kNonNegative});
  v.param("debris_c_max", debris_c_max,
          {.unit = "1",
           .description = "debris-short threshold cap c_max",
           .range = rt::closed(0.0, 1.0)});
  v.param("debris_k_s", debris_k_s,
          {.unit = "1",
           .description = "debris-short sigmoid steepness k_s",
           .range = rt::kNonNegative});
  v.param(
      "debris_short_us", debris_short_us,
      {.unit = "us", .description = "t_bs: duration of a debris short", .range = rt::kPositive});
  v.param("short_events", short_events,
          {.unit = "",
           .description = "debris bridges and tube vibration contacts (false: the model before "
                          "edm-sim-params/7)"});
  v.param("bridge_rate_hz", bridge_rate_hz,
          {.unit = "1/s",
           .description = "lambda_b0: bridges per second at c = c_b at the surface",
           .range = rt::kNonNegative});
  v.param("bridge_debris_ref", bridge_debris_ref,
          {.unit = "1",
           .description = "c_b: reference debris of the bridge hazard",
           .range = rt::open_closed(0.0, 1.0)});
  v.param("bridge_debris_exp", bridge_debris_exp,
          {.unit = "1",
           .description = "n_b: bridge hazard grows as (c/c_b)^n_b",
           .range = rt::kNonNegative});
  v.param("bridge_depth_mm", bridge_depth_mm,
          {.unit = "mm",
           .description = "h_b: bridge hazard grows as 1 + h/h_b",
           .range = rt::kPositive});
  v.param(
      "bridge_mean_ms", bridge_mean_ms,
      {.unit = "ms", .description = "t_b: mean life of a debris bridge", .range = rt::kPositive});
  v.param("bridge_clear_um", bridge_clear_um,
          {.unit = "um",
           .description = "a back-off of the tip this large breaks a bridge",
           .range = rt::kPositive});
  v.param("tube_guide_mm", tube_guide_mm,
          {.unit = "mm",
           .description = "tube: free length between the guide and the surface",
           .range = rt::kNonNegative});
  v.param("vib_amp_ref_um", vib_amp_ref_um,
          {.unit = "um",
           .description = "tube: RMS lateral tip deflection at the free length L_ref (0: none)",
           .range = rt::kNonNegative});
  v.param(
      "vib_len_ref_mm", vib_len_ref_mm,
      {.unit = "mm", .description = "tube: reference free length L_ref", .range = rt::kPositive});
  v.param("vib_amp_exp", vib_amp_exp,
          {.unit = "1",
           .description = "tube: deflection grows as (L/L_ref)^this",
           .range = rt::kNonNegative});
  v.param("vib_freq_ref_hz", vib_freq_ref_hz,
          {.unit = "Hz",
           .description = "tube: first bending frequency at L_ref (scales as (L_ref/L)^2)",
           .range = rt::kPositive});
  v.param(
      "contact_at_depth_mm", contact_at_depth_mm,
      {.unit = "mm",
       .description = "injection: a hard contact meets the tip at this hole depth (<= 0: off)"});
  v.param("contact_clear_um", contact_clear_um,
          {.unit = "um",
           .description = "injection: the tip backed off this far from the contact is clear of it",
           .range = rt::kPositive});
  v.param("contact_persistent", contact_persistent,
          {.unit = "",
           .description = "injection: the contact stays (every re-approach meets it again)"});
}

void SimParams::visit_arcs(rt::ParamVisitor& v) {
  v.param(
      "arc_p0", arc_p0,
      {.unit = "1", .description = "arc probability floor p_a0", .range = rt::closed(0.0, 1.0)});
  v.param("arc_k_t", arc_k_t,
          {.unit = "1",
           .description = "arc weight of a not-deionised channel k_t",
           .range = rt::kNonNegative});
  v.param("deion_us", deion_us,
          {.unit = "us", .description = "deionisation time tau_di", .range = rt::kPositive});
  v.param("arc_k_c", arc_k_c,
          {.unit = "1", .description = "arc weight of debris k_c", .range = rt::kNonNegative});
  v.param("arc_k_g", arc_k_g,
          {.unit = "1", .description = "arc weight of a small gap k_g", .range = rt::kNonNegative});
  v.param("arc_gap_um", arc_gap_um,
          {.unit = "um", .description = "arc gap scale g_a", .range = rt::kPositive});
  v.param("arc_p_max", arc_p_max,
          {.unit = "1", .description = "arc probability cap", .range = rt::closed(0.0, 1.0)});
}

void SimParams::visit_removal(rt::ParamVisitor& v) {
  v.param("removal_mm3_per_j", removal_mm3_per_j,
          {.unit = "mm3/J",
           .description = "eta: removal per discharge energy (0: crater law)",
           .range = rt::kNonNegative});
  v.param("crater_ref_um3", crater_ref_um3,
          {.unit = "um3",
           .description = "crater volume at 1 A (crater law; 0: removal_mm3_per_j)",
           .range = rt::kNonNegative});
  v.param("crater_exp", crater_exp,
          {.unit = "1", .description = "crater law exponent on Ip", .range = rt::kNonNegative});
  v.param(
      "removal_sigma", removal_sigma,
      {.unit = "1", .description = "sigma_v: relative crater scatter", .range = rt::kNonNegative});
  v.param("arc_removal_ratio", arc_removal_ratio,
          {.unit = "1",
           .description = "alpha_arc: arc removal / spark removal",
           .range = rt::kNonNegative});
  v.param(
      "arc_wear_factor", arc_wear_factor,
      {.unit = "1", .description = "wear ratio multiplier for arcs", .range = rt::kNonNegative});
  v.param("wear_ratio", wear_ratio,
          {.unit = "1",
           .description = "theta: electrode/work volume, negative polarity",
           .range = rt::kNonNegative});
  v.param("wear_ratio_positive", wear_ratio_positive,
          {.unit = "1", .description = "theta for positive polarity", .range = rt::kNonNegative});
  v.param("removal_scale_positive", removal_scale_positive,
          {.unit = "1", .description = "removal x this, positive pol.", .range = rt::kNonNegative});
}

void SimParams::visit_electrode(rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("tool_kind", tool_kind, {.unit = "", .description = "tube | block | wire"});
  v.param("tool_od_mm", tool_od_mm, {.unit = "mm", .description = "tube outer diameter"});
  v.param("tool_id_mm", tool_id_mm, {.unit = "mm", .description = "tube inner diameter"});
  v.param("hole_d_mm", hole_d_mm, {.unit = "mm", .description = "tube: initial hole diameter"});
  v.param("side_gap_mm", side_gap_mm, {.unit = "mm", .description = "block: side gap per side"});
  v.param("tool_width_mm", tool_width_mm, {.unit = "mm", .description = "block width"});
  v.param("tool_length_mm", tool_length_mm, {.unit = "mm", .description = "block length"});
  v.param("wire_d_mm", wire_d_mm, {.unit = "mm", .description = "wire diameter D"});
  // Through `writable`, runtime-writable: the retained electrode length is restored through this
  // (§5a). Its range: 100 km, the wire on a spool (20 kg of Ø0.25 mm brass is ~48 km; the wire
  // preset has 1 km); the hole's below: 5 m, beyond any EDM machine's travel.
  writable.param("electrode_length_mm", electrode_length_mm,
                 {.unit = "mm",
                  .description = "electrode length; reads the length left, a runtime write sets it",
                  .range = rt::closed(0.0, 1.0e8)});
  v.param(
      "work_thickness_mm", work_thickness_mm,
      {.unit = "mm", .description = "through at this depth (0: blind)", .range = rt::kNonNegative});
  v.param("start_gap_um", start_gap_um,
          {.unit = "um",
           .description = "tip above the work surface at start",
           .range = rt::kNonNegative});
  v.param("initial_depth_mm", initial_depth_mm,
          {.unit = "mm",
           .description = "tube/block: a hole this deep is already there under the electrode; the "
                          "tip starts start_gap_um above its bottom",
           .range = rt::kNonNegative});
}

void SimParams::visit_work(rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("work_surface_z_mm", work_surface_z_mm,
          {.unit = "mm", .description = "machine Z of the work's top surface"});
  v.param("work_origin_x_mm", work_origin_x_mm,
          {.unit = "mm", .description = "machine X of the work's datum"});
  v.param("work_origin_y_mm", work_origin_y_mm,
          {.unit = "mm", .description = "machine Y of the work's datum"});
  v.param("work_x_min_mm", work_x_min_mm,
          {.unit = "mm", .description = "work block: lowest X, relative to the datum"});
  v.param("work_x_max_mm", work_x_max_mm,
          {.unit = "mm", .description = "work block: highest X, relative to the datum (> min)"});
  v.param("work_y_min_mm", work_y_min_mm,
          {.unit = "mm", .description = "work block: lowest Y, relative to the datum"});
  v.param("work_y_max_mm", work_y_max_mm,
          {.unit = "mm", .description = "work block: highest Y, relative to the datum (> min)"});
  v.param("work_bore_x_mm", work_bore_x_mm,
          {.unit = "mm", .description = "through bore: centre X relative to the datum"});
  v.param("work_bore_y_mm", work_bore_y_mm,
          {.unit = "mm", .description = "through bore: centre Y relative to the datum"});
  v.param("work_bore_d_mm", work_bore_d_mm,
          {.unit = "mm",
           .description = "through bore diameter, inside the block (0: none)",
           .range = rt::kNonNegative});
  v.param("start_x_mm", start_x_mm,
          {.unit = "mm", .description = "machine X of the electrode at power-on"});
  v.param("start_y_mm", start_y_mm,
          {.unit = "mm", .description = "machine Y of the electrode at power-on"});
  v.param("ref_x_mm", ref_x_mm,
          {.unit = "mm", .description = "X reference switch: on at or beyond this machine X"});
  v.param("ref_y_mm", ref_y_mm,
          {.unit = "mm", .description = "Y reference switch: on at or beyond this machine Y"});
  v.param("ref_z_mm", ref_z_mm,
          {.unit = "mm", .description = "Z reference switch: on at or beyond this machine Z"});
  v.param("ref_repeat_um", ref_repeat_um,
          {.unit = "um",
           .description = "reference switches: SD of the trip point, drawn anew per trip",
           .range = rt::kNonNegative});
  v.param("ref_hysteresis_um", ref_hysteresis_um,
          {.unit = "um",
           .description = "reference switches: release this far below the trip point",
           .range = rt::kNonNegative});
  v.param("encoder_offset_x_mm", encoder_offset_x_mm,
          {.unit = "mm", .description = "X encoder reads machine X - this at power-on"});
  v.param("encoder_offset_y_mm", encoder_offset_y_mm,
          {.unit = "mm", .description = "Y encoder reads machine Y - this at power-on"});
  v.param("encoder_offset_z_mm", encoder_offset_z_mm,
          {.unit = "mm", .description = "Z encoder reads machine Z - this at power-on"});
  v.param("touch_gap_um", touch_gap_um,
          {.unit = "um",
           .description = "touch mode: contact within this distance of the work's material",
           .range = rt::kNonNegative});
  v.param("touch_noise_um", touch_noise_um,
          {.unit = "um",
           .description = "touch mode: SD of that distance, drawn anew per contact",
           .range = rt::kNonNegative});
  v.param("touch_voltage_v", touch_voltage_v,
          {.unit = "V",
           .description = "touch mode: gap voltage while open (0 V in contact)",
           .range = rt::kNonNegative});
  // Through `writable`, runtime-writable: a retain store restores the hole through these
  // (docs/simulator.md §5a).
  writable.param("hole_depth_mm", hole_depth_mm,
                 {.unit = "mm",
                  .description = "the hole in the work: reads its live depth, a write sets it",
                  .range = rt::closed(0.0, 5000.0)});
  writable.param("hole_x_mm", hole_x_mm,
                 {.unit = "mm",
                  .description = "the hole's axis, machine X: reads the live one, a write sets it",
                  .range = rt::closed(-5000.0, 5000.0)});
  writable.param("hole_y_mm", hole_y_mm,
                 {.unit = "mm",
                  .description = "the hole's axis, machine Y: reads the live one, a write sets it",
                  .range = rt::closed(-5000.0, 5000.0)});
}

void SimParams::visit_flushing(rt::ParamVisitor& v) {
  v.param("debris_kappa", debris_kappa,
          {.unit = "1", .description = "kappa: c += kappa V / V_gap", .range = rt::kNonNegative});
  v.param(
      "debris_flush_k", debris_flush_k,
      {.unit = "1", .description = "k in the flushing term exp(-k c)", .range = rt::kNonNegative});
  v.param("flush_tau0_ms", flush_tau0_ms,
          {.unit = "ms",
           .description = "tau_f0: flushing time constant at the surface",
           .range = rt::kPositive});
  v.param(
      "flush_depth_mm", flush_depth_mm,
      {.unit = "mm", .description = "h_f: tau_f = tau_f0 (1 + (h/h_f)^2)", .range = rt::kPositive});
  v.param("flush_gap_ref_um", flush_gap_ref_um,
          {.unit = "um",
           .description = "g_ref: flushing x min(1, (g/g_ref)^3)",
           .range = rt::kPositive});
  v.param(
      "flush_factor", flush_factor,
      {.unit = "1", .description = "F: scenario flushing factor", .range = rt::closed(0.0, 1.0)});
  v.param(
      "flush_drop_depth_mm", flush_drop_depth_mm,
      {.unit = "mm", .description = "scenario: F drops beyond depth", .range = rt::kNonNegative});
  v.param("flush_drop_factor", flush_drop_factor,
          {.unit = "1",
           .description = "scenario: F x this beyond that depth",
           .range = rt::kNonNegative});
  v.param("near_tip_zone_mm", near_tip_zone_mm,
          {.unit = "mm", .description = "l_z: side zone near the tip", .range = rt::kPositive});
  v.param("jump_dz_mm", jump_dz_mm,
          {.unit = "mm",
           .description = "a retract longer than this is a jump",
           .range = rt::kPositive});
  v.param("jump_eps", jump_eps,
          {.unit = "1",
           .description = "a jump multiplies c by (1 - jump_eps)",
           .range = rt::closed(0.0, 1.0)});
  v.param("wall_sparks", wall_sparks,
          {.unit = "", .description = "tube: wall bins compete with the front (orbit)"});
}

void SimParams::visit_axes(rt::ParamVisitor& v) {
  v.param(
      "axis_wn_rad_s", axis_wn_rad_s,
      {.unit = "rad/s", .description = "position loop natural frequency", .range = rt::kPositive});
  v.param("axis_zeta", axis_zeta,
          {.unit = "1", .description = "position loop damping", .range = rt::kPositive});
  v.param("v_max_mm_s", v_max_mm_s,
          {.unit = "mm/s",
           .description = "feed speed limit (toward the work, x, y)",
           .range = rt::kPositive});
  v.param("v_jump_mm_s", v_jump_mm_s,
          {.unit = "mm/s",
           .description = "retract speed limit (z away from the work)",
           .range = rt::kPositive});
  v.param("a_max_mm_s2", a_max_mm_s2,
          {.unit = "mm/s2", .description = "acceleration limit", .range = rt::kPositive});
  v.param("encoder_um", encoder_um,
          {.unit = "um",
           .description = "encoder quantum of reported positions",
           .range = rt::kNonNegative});
  v.param(
      "servo_gain_mm_s_per_v", servo_gain_mm_s_per_v,
      {.unit = "mm/s/V",
       .description =
           "machine servo gain k: vz += -k (U_av - servo_ref_v) while servo_ref_v > 0 (0: none)",
       .range = rt::kNonNegative});
  v.param(
      "axis_step_us", axis_step_us,
      {.unit = "us", .description = "axis integration sub-step", .range = rt::closed(1.0, 50.0)});
}

void SimParams::visit_wire(rt::ParamVisitor& v) {
  v.param("wire_thickness_profile", wire_thickness_profile,
          {.unit = "mm:mm", .description = "cut length:thickness,..."});
  v.param("wire_hole_from_mm", wire_hole_from_mm,
          {.unit = "mm",
           .description = "internal hole starts at this length",
           .range = rt::kNonNegative});
  v.param("wire_hole_to_mm", wire_hole_to_mm,
          {.unit = "mm", .description = "internal hole ends at this length"});
  v.param("wire_ibk_ref_a", wire_ibk_ref_a,
          {.unit = "A",
           .description = "break current I_BK at H = 10 mm, f = 1",
           .range = rt::kPositive});
  v.param(
      "wire_flush_floor", wire_flush_floor,
      {.unit = "1", .description = "f = floor + (1 - floor) F_eff", .range = rt::closed(0.0, 1.0)});
  v.param("wire_break_current_ms", wire_break_current_ms,
          {.unit = "ms", .description = "break after mean I > I_BK this", .range = rt::kPositive});
  v.param("wire_break_rab", wire_break_rab,
          {.unit = "1",
           .description = "rupture hazard: at this Rab ...",
           .range = rt::closed(0.0, 1.0)});
  v.param(
      "wire_break_rab_ms", wire_break_rab_ms,
      {.unit = "ms", .description = "... the mean time to break is this", .range = rt::kPositive});
  v.param("wire_break_rab_width", wire_break_rab_width,
          {.unit = "1", .description = "hazard x e per this Rab above", .range = rt::kPositive});
  v.param("wire_break_rab_tau_ms", wire_break_rab_tau_ms,
          {.unit = "ms", .description = "hazard acts on Rab lagged by", .range = rt::kPositive});
  v.param("wire_break_rab_shape", wire_break_rab_shape,
          {.unit = "1",
           .description = "k: tolerated damage ~ Gamma(k, 1/k), a whole number",
           .range = rt::closed(1.0, static_cast<double>(kMaxWireBreakShape))});
  v.param("wire_kerf_debris_per_mm", wire_kerf_debris_per_mm,
          {.unit = "1/mm",
           .description = "kerf debris c_k added per mm of cut (0 = no kerf debris)",
           .range = rt::kNonNegative});
  v.param("wire_kerf_flush_s", wire_kerf_flush_s,
          {.unit = "s",
           .description = "tau_k of the kerf debris at H = 10 mm",
           .range = rt::kPositive});
  v.param("wire_kerf_flush_exp", wire_kerf_flush_exp,
          {.unit = "1", .description = "tau_k grows as (H/10 mm)^this", .range = rt::kNonNegative});
  v.param("wire_nozzle_radius_mm", wire_nozzle_radius_mm,
          {.unit = "mm", .description = "flushing nozzle radius", .range = rt::kNonNegative});
  v.param("wire_hole_flush_factor", wire_hole_flush_factor,
          {.unit = "1",
           .description = "F_eff x this while the nozzle overlaps the internal hole",
           .range = rt::closed(0.0, 1.0)});
  v.param("wire_cavity_from_mm", wire_cavity_from_mm,
          {.unit = "mm",
           .description = "internal cavity starts at this length",
           .range = rt::kNonNegative});
  v.param("wire_cavity_to_mm", wire_cavity_to_mm,
          {.unit = "mm", .description = "internal cavity ends (far wall) here"});
  v.param("wire_cavity_height_mm", wire_cavity_height_mm,
          {.unit = "mm",
           .description = "void height of the cavity, centred in H, < H over the cavity",
           .range = rt::kNonNegative});
  v.param("wire_cavity_flush_factor", wire_cavity_flush_factor,
          {.unit = "1",
           .description = "flush of the wire's centre part at the cavity's far wall",
           .range = rt::closed(0.0, 1.0)});
  v.param("wire_cavity_flush_mm", wire_cavity_flush_mm,
          {.unit = "mm",
           .description = "that flush loss fades e-fold per this much cut past the far wall",
           .range = rt::kPositive});
  v.param("wire_cavity_debris", wire_cavity_debris,
          {.unit = "1",
           .description = "debris of the cavity's stagnant dielectric, met at the far wall",
           .range = rt::closed(0.0, 1.0)});
  v.param("mean_current_ema_ms", mean_current_ema_ms,
          {.unit = "ms", .description = "time constant of mean current", .range = rt::kPositive});
}

void SimParams::visit_sensors(rt::ParamVisitor& v) {
  v.param("rab_window_ms", rab_window_ms,
          {.unit = "ms", .description = "Rab window", .range = rt::kPositive});
  v.param("mean_voltage_tau_ms", mean_voltage_tau_ms,
          {.unit = "ms", .description = "U_av filter time constant", .range = rt::kPositive});
  v.param("td_quantum_ns", td_quantum_ns,
          {.unit = "ns", .description = "Td quantisation (FPGA)", .range = rt::at_least(1.0)});
  v.param("max_pulses_per_advance", max_pulses_per_advance,
          {.unit = "1", .description = "pulse budget per advance_to", .range = rt::at_least(1.0)});
}

}  // namespace edm::sim
