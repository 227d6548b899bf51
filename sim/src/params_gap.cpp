#include "params_visit.hpp"

// The gap model's part of SimParams::visit (params_visit.hpp): the generator, the ignition delay,
// shorts, arcs, removal and wear, debris and flushing, the sensors.

namespace edm::sim {

namespace rt = edm::rt;

void visit_generator(SimParams& p, rt::ParamVisitor& v) {
  v.param("open_voltage_v", p.open_voltage_v,
          {.unit = "V", .description = "open-circuit voltage U0", .range = rt::kPositive});
  v.param("discharge_voltage_v", p.discharge_voltage_v,
          {.unit = "V", .description = "discharge voltage U_d", .range = rt::kPositive});
  v.param("arc_voltage_v", p.arc_voltage_v,
          {.unit = "V", .description = "arc voltage U_arc", .range = rt::kNonNegative});
  v.param("short_voltage_v", p.short_voltage_v,
          {.unit = "V", .description = "short-circuit voltage U_sh", .range = rt::kNonNegative});
  v.param("peak_current_a", p.peak_current_a,
          {.unit = "A", .description = "peak current Ip", .range = rt::kPositive});
  v.param("default_on_time_us", p.default_on_time_us,
          {.unit = "us", .description = "default on time t_on", .range = rt::kPositive});
  v.param("default_off_time_us", p.default_off_time_us,
          {.unit = "us", .description = "default off time t_off", .range = rt::kPositive});
  v.param("default_arc_off_time_us", p.default_arc_off_time_us,
          {.unit = "us",
           .description = "default off time after abnormal pulses",
           .range = rt::kPositive});
  v.param("wait_time_us", p.wait_time_us,
          {.unit = "us",
           .description = "T_wait: no ignition by then means an open pulse",
           .range = rt::kPositive});
}

void visit_ignition(SimParams& p, rt::ParamVisitor& v) {
  v.param("td_law", p.td_law,
          {.unit = "", .description = "ignition-delay median law: exp | quadratic"});
  v.param("td_gap_ref_um", p.td_gap_ref_um,
          {.unit = "um", .description = "exp law: reference gap g_r"});
  v.param("td_tau_ref_us", p.td_tau_ref_us,
          {.unit = "us", .description = "exp law: median at g_r, tau_r", .range = rt::kPositive});
  v.param("td_len_um", p.td_len_um,
          {.unit = "um", .description = "exp law: gap per e-fold l_g", .range = rt::kPositive});
  v.param("td_tau_min_us", p.td_tau_min_us,
          {.unit = "us", .description = "exp law: floor tau_min", .range = rt::kNonNegative});
  v.param("td_quad_a_us", p.td_quad_a_us,
          {.unit = "us/um2", .description = "quadratic law: a in a g^2 + b g + c"});
  v.param("td_quad_b_us", p.td_quad_b_us, {.unit = "us/um", .description = "quadratic law: b"});
  v.param("td_quad_c_us", p.td_quad_c_us, {.unit = "us", .description = "quadratic law: c"});
  v.param(
      "td_quad_max_gap_um", p.td_quad_max_gap_um,
      {.unit = "um", .description = "quadratic law: no ignition beyond", .range = rt::kPositive});
  v.param("weibull_k", p.weibull_k,
          {.unit = "1",
           .description = "Weibull shape of Td (1 = exponential)",
           .range = rt::kPositive});
  v.param("td_debris_k", p.td_debris_k,
          {.unit = "1",
           .description = "k_cd: median scales with exp(-k_cd c)",
           .range = rt::kNonNegative});
  v.param("arc_td_max_us", p.arc_td_max_us,
          {.unit = "us",
           .description = "arc ignition delay is uniform in [0, this)",
           .range = rt::kNonNegative});
}

void visit_shorts(SimParams& p, rt::ParamVisitor& v) {
  v.param("short_gap_um", p.short_gap_um,
          {.unit = "um",
           .description = "g_c: hard short at or below this gap",
           .range = rt::kNonNegative});
  v.param("debris_c0", p.debris_c0,
          {.unit = "1", .description = "debris-short threshold c0", .range = rt::closed(0.0, 1.0)});
  v.param("debris_a_g_per_um", p.debris_a_g_per_um,
          {.unit = "1/um",
           .description = "debris-short threshold slope a_g",
           .range = rt::kNonNegative});
  v.param("debris_c_max", p.debris_c_max,
          {.unit = "1",
           .description = "debris-short threshold cap c_max",
           .range = rt::closed(0.0, 1.0)});
  v.param("debris_k_s", p.debris_k_s,
          {.unit = "1",
           .description = "debris-short sigmoid steepness k_s",
           .range = rt::kNonNegative});
  v.param(
      "debris_short_us", p.debris_short_us,
      {.unit = "us", .description = "t_bs: duration of a debris short", .range = rt::kPositive});
  v.param("short_events", p.short_events,
          {.unit = "",
           .description = "debris bridges and tube vibration contacts (false: the model before "
                          "edm-sim-params/7)"});
  v.param("bridge_rate_hz", p.bridge_rate_hz,
          {.unit = "1/s",
           .description = "lambda_b0: bridges per second at c = c_b at the surface",
           .range = rt::kNonNegative});
  v.param("bridge_debris_ref", p.bridge_debris_ref,
          {.unit = "1",
           .description = "c_b: reference debris of the bridge hazard",
           .range = rt::open_closed(0.0, 1.0)});
  v.param("bridge_debris_exp", p.bridge_debris_exp,
          {.unit = "1",
           .description = "n_b: bridge hazard grows as (c/c_b)^n_b",
           .range = rt::kNonNegative});
  v.param("bridge_depth_mm", p.bridge_depth_mm,
          {.unit = "mm",
           .description = "h_b: bridge hazard grows as 1 + h/h_b",
           .range = rt::kPositive});
  v.param(
      "bridge_mean_ms", p.bridge_mean_ms,
      {.unit = "ms", .description = "t_b: mean life of a debris bridge", .range = rt::kPositive});
  v.param("bridge_clear_um", p.bridge_clear_um,
          {.unit = "um",
           .description = "a back-off of the tip this large breaks a bridge",
           .range = rt::kPositive});
  v.param("tube_guide_mm", p.tube_guide_mm,
          {.unit = "mm",
           .description = "tube: free length between the guide and the surface",
           .range = rt::kNonNegative});
  v.param("vib_amp_ref_um", p.vib_amp_ref_um,
          {.unit = "um",
           .description = "tube: RMS lateral tip deflection at the free length L_ref (0: none)",
           .range = rt::kNonNegative});
  v.param(
      "vib_len_ref_mm", p.vib_len_ref_mm,
      {.unit = "mm", .description = "tube: reference free length L_ref", .range = rt::kPositive});
  v.param("vib_amp_exp", p.vib_amp_exp,
          {.unit = "1",
           .description = "tube: deflection grows as (L/L_ref)^this",
           .range = rt::kNonNegative});
  v.param("vib_freq_ref_hz", p.vib_freq_ref_hz,
          {.unit = "Hz",
           .description = "tube: first bending frequency at L_ref (scales as (L_ref/L)^2)",
           .range = rt::kPositive});
  v.param(
      "contact_at_depth_mm", p.contact_at_depth_mm,
      {.unit = "mm",
       .description = "injection: a hard contact meets the tip at this hole depth (<= 0: off)"});
  v.param("contact_clear_um", p.contact_clear_um,
          {.unit = "um",
           .description = "injection: the tip backed off this far from the contact is clear of it",
           .range = rt::kPositive});
  v.param("contact_persistent", p.contact_persistent,
          {.unit = "",
           .description = "injection: the contact stays (every re-approach meets it again)"});
}

void visit_arcs(SimParams& p, rt::ParamVisitor& v) {
  v.param(
      "arc_p0", p.arc_p0,
      {.unit = "1", .description = "arc probability floor p_a0", .range = rt::closed(0.0, 1.0)});
  v.param("arc_k_t", p.arc_k_t,
          {.unit = "1",
           .description = "arc weight of a not-deionised channel k_t",
           .range = rt::kNonNegative});
  v.param("deion_us", p.deion_us,
          {.unit = "us", .description = "deionisation time tau_di", .range = rt::kPositive});
  v.param("arc_k_c", p.arc_k_c,
          {.unit = "1", .description = "arc weight of debris k_c", .range = rt::kNonNegative});
  v.param("arc_k_g", p.arc_k_g,
          {.unit = "1", .description = "arc weight of a small gap k_g", .range = rt::kNonNegative});
  v.param("arc_gap_um", p.arc_gap_um,
          {.unit = "um", .description = "arc gap scale g_a", .range = rt::kPositive});
  v.param("arc_p_max", p.arc_p_max,
          {.unit = "1", .description = "arc probability cap", .range = rt::closed(0.0, 1.0)});
}

void visit_removal(SimParams& p, rt::ParamVisitor& v) {
  v.param("removal_mm3_per_j", p.removal_mm3_per_j,
          {.unit = "mm3/J",
           .description = "eta: removal per discharge energy (0: crater law)",
           .range = rt::kNonNegative});
  v.param("crater_ref_um3", p.crater_ref_um3,
          {.unit = "um3",
           .description = "crater volume at 1 A (crater law; 0: removal_mm3_per_j)",
           .range = rt::kNonNegative});
  v.param("crater_exp", p.crater_exp,
          {.unit = "1", .description = "crater law exponent on Ip", .range = rt::kNonNegative});
  v.param(
      "removal_sigma", p.removal_sigma,
      {.unit = "1", .description = "sigma_v: relative crater scatter", .range = rt::kNonNegative});
  v.param("arc_removal_ratio", p.arc_removal_ratio,
          {.unit = "1",
           .description = "alpha_arc: arc removal / spark removal",
           .range = rt::kNonNegative});
  v.param(
      "arc_wear_factor", p.arc_wear_factor,
      {.unit = "1", .description = "wear ratio multiplier for arcs", .range = rt::kNonNegative});
  v.param("wear_ratio", p.wear_ratio,
          {.unit = "1",
           .description = "theta: electrode/work volume, negative polarity",
           .range = rt::kNonNegative});
  v.param("wear_ratio_positive", p.wear_ratio_positive,
          {.unit = "1", .description = "theta for positive polarity", .range = rt::kNonNegative});
  v.param("removal_scale_positive", p.removal_scale_positive,
          {.unit = "1", .description = "removal x this, positive pol.", .range = rt::kNonNegative});
}

void visit_flushing(SimParams& p, rt::ParamVisitor& v) {
  v.param("debris_kappa", p.debris_kappa,
          {.unit = "1", .description = "kappa: c += kappa V / V_gap", .range = rt::kNonNegative});
  v.param(
      "debris_flush_k", p.debris_flush_k,
      {.unit = "1", .description = "k in the flushing term exp(-k c)", .range = rt::kNonNegative});
  v.param("flush_tau0_ms", p.flush_tau0_ms,
          {.unit = "ms",
           .description = "tau_f0: flushing time constant at the surface",
           .range = rt::kPositive});
  v.param(
      "flush_depth_mm", p.flush_depth_mm,
      {.unit = "mm", .description = "h_f: tau_f = tau_f0 (1 + (h/h_f)^2)", .range = rt::kPositive});
  v.param("flush_gap_ref_um", p.flush_gap_ref_um,
          {.unit = "um",
           .description = "g_ref: flushing x min(1, (g/g_ref)^3)",
           .range = rt::kPositive});
  v.param(
      "flush_factor", p.flush_factor,
      {.unit = "1", .description = "F: scenario flushing factor", .range = rt::closed(0.0, 1.0)});
  v.param(
      "flush_drop_depth_mm", p.flush_drop_depth_mm,
      {.unit = "mm", .description = "scenario: F drops beyond depth", .range = rt::kNonNegative});
  v.param("flush_drop_factor", p.flush_drop_factor,
          {.unit = "1",
           .description = "scenario: F x this beyond that depth",
           .range = rt::kNonNegative});
  v.param("near_tip_zone_mm", p.near_tip_zone_mm,
          {.unit = "mm", .description = "l_z: side zone near the tip", .range = rt::kPositive});
  v.param("jump_dz_mm", p.jump_dz_mm,
          {.unit = "mm",
           .description = "a retract longer than this is a jump",
           .range = rt::kPositive});
  v.param("jump_eps", p.jump_eps,
          {.unit = "1",
           .description = "a jump multiplies c by (1 - jump_eps)",
           .range = rt::closed(0.0, 1.0)});
  v.param("wall_sparks", p.wall_sparks,
          {.unit = "", .description = "tube: wall bins compete with the front (orbit)"});
}

void visit_sensors(SimParams& p, rt::ParamVisitor& v) {
  v.param("rab_window_ms", p.rab_window_ms,
          {.unit = "ms", .description = "Rab window", .range = rt::kPositive});
  v.param("mean_voltage_tau_ms", p.mean_voltage_tau_ms,
          {.unit = "ms", .description = "U_av filter time constant", .range = rt::kPositive});
  v.param("td_quantum_ns", p.td_quantum_ns,
          {.unit = "ns", .description = "Td quantisation (FPGA)", .range = rt::at_least(1.0)});
  v.param("max_pulses_per_advance", p.max_pulses_per_advance,
          {.unit = "1", .description = "pulse budget per advance_to", .range = rt::at_least(1.0)});
}

}  // namespace edm::sim
