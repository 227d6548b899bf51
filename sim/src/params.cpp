#include "edm/sim/params.hpp"

// The simulator's parameter schema (visit) and its validation. The presets are presets.cpp, the
// thickness-profile parser thickness_profile.cpp.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace edm::sim {

namespace rt = edm::rt;

void SimParams::visit(rt::ParamVisitor& v) {
  v.param("open_voltage_v", open_voltage_v, "V", "open-circuit voltage U0");
  v.param("discharge_voltage_v", discharge_voltage_v, "V", "discharge voltage U_d");
  v.param("arc_voltage_v", arc_voltage_v, "V", "arc voltage U_arc");
  v.param("short_voltage_v", short_voltage_v, "V", "short-circuit voltage U_sh");
  v.param("peak_current_a", peak_current_a, "A", "peak current Ip");
  v.param("default_on_time_us", default_on_time_us, "us", "default on time t_on");
  v.param("default_off_time_us", default_off_time_us, "us", "default off time t_off");
  v.param("default_arc_off_time_us", default_arc_off_time_us, "us",
          "default off time after abnormal pulses");
  v.param("wait_time_us", wait_time_us, "us", "T_wait: no ignition by then means an open pulse");
  v.param("td_law", td_law, "", "ignition-delay median law: exp | quadratic");
  v.param("td_gap_ref_um", td_gap_ref_um, "um", "exp law: reference gap g_r");
  v.param("td_tau_ref_us", td_tau_ref_us, "us", "exp law: median at g_r, tau_r");
  v.param("td_len_um", td_len_um, "um", "exp law: gap per e-fold l_g");
  v.param("td_tau_min_us", td_tau_min_us, "us", "exp law: floor tau_min");
  v.param("td_quad_a_us", td_quad_a_us, "us/um2", "quadratic law: a in a g^2 + b g + c");
  v.param("td_quad_b_us", td_quad_b_us, "us/um", "quadratic law: b");
  v.param("td_quad_c_us", td_quad_c_us, "us", "quadratic law: c");
  v.param("td_quad_max_gap_um", td_quad_max_gap_um, "um", "quadratic law: no ignition beyond");
  v.param("weibull_k", weibull_k, "1", "Weibull shape of Td (1 = exponential)");
  v.param("td_debris_k", td_debris_k, "1", "k_cd: median scales with exp(-k_cd c)");
  v.param("arc_td_max_us", arc_td_max_us, "us", "arc ignition delay is uniform in [0, this)");
  v.param("short_gap_um", short_gap_um, "um", "g_c: hard short at or below this gap");
  v.param("debris_c0", debris_c0, "1", "debris-short threshold c0");
  v.param("debris_a_g_per_um", debris_a_g_per_um, "1/um", "debris-short threshold slope a_g");
  v.param("debris_c_max", debris_c_max, "1", "debris-short threshold cap c_max");
  v.param("debris_k_s", debris_k_s, "1", "debris-short sigmoid steepness k_s");
  v.param("debris_short_us", debris_short_us, "us", "t_bs: duration of a debris short");
  v.param("arc_p0", arc_p0, "1", "arc probability floor p_a0");
  v.param("arc_k_t", arc_k_t, "1", "arc weight of a not-deionised channel k_t");
  v.param("deion_us", deion_us, "us", "deionisation time tau_di");
  v.param("arc_k_c", arc_k_c, "1", "arc weight of debris k_c");
  v.param("arc_k_g", arc_k_g, "1", "arc weight of a small gap k_g");
  v.param("arc_gap_um", arc_gap_um, "um", "arc gap scale g_a");
  v.param("arc_p_max", arc_p_max, "1", "arc probability cap");
  v.param("removal_mm3_per_j", removal_mm3_per_j, "mm3/J", "eta: removal per discharge energy");
  v.param("crater_ref_um3", crater_ref_um3, "um3", ">0: crater volume at 1 A (crater law)");
  v.param("crater_exp", crater_exp, "1", "crater law exponent on Ip");
  v.param("removal_sigma", removal_sigma, "1", "sigma_v: relative crater scatter");
  v.param("arc_removal_ratio", arc_removal_ratio, "1", "alpha_arc: arc removal / spark removal");
  v.param("arc_wear_factor", arc_wear_factor, "1", "wear ratio multiplier for arcs");
  v.param("wear_ratio", wear_ratio, "1", "theta: electrode/work volume, negative polarity");
  v.param("wear_ratio_positive", wear_ratio_positive, "1", "theta for positive polarity");
  v.param("removal_scale_positive", removal_scale_positive, "1", "removal x this, positive pol.");
  v.param("tool_kind", tool_kind, "", "tube | block | wire");
  v.param("tool_od_mm", tool_od_mm, "mm", "tube outer diameter");
  v.param("tool_id_mm", tool_id_mm, "mm", "tube inner diameter");
  v.param("hole_d_mm", hole_d_mm, "mm", "tube: initial hole diameter");
  v.param("side_gap_mm", side_gap_mm, "mm", "block: side gap per side");
  v.param("tool_width_mm", tool_width_mm, "mm", "block width");
  v.param("tool_length_mm", tool_length_mm, "mm", "block length");
  v.param("wire_d_mm", wire_d_mm, "mm", "wire diameter D");
  v.param("electrode_length_mm", electrode_length_mm, "mm", "electrode length at start");
  v.param("work_thickness_mm", work_thickness_mm, "mm", "through at this depth; 0 = blind");
  v.param("start_gap_um", start_gap_um, "um", "tip above the work surface at start");
  v.param("initial_depth_mm", initial_depth_mm, "mm",
          "tube/block: a hole this deep is already there under the electrode; the tip starts "
          "start_gap_um above its bottom");
  v.param("debris_kappa", debris_kappa, "1", "kappa: c += kappa V / V_gap");
  v.param("debris_flush_k", debris_flush_k, "1", "k in the flushing term exp(-k c)");
  v.param("flush_tau0_ms", flush_tau0_ms, "ms", "tau_f0: flushing time constant at the surface");
  v.param("flush_depth_mm", flush_depth_mm, "mm", "h_f: tau_f = tau_f0 (1 + (h/h_f)^2)");
  v.param("flush_gap_ref_um", flush_gap_ref_um, "um", "g_ref: flushing x min(1, (g/g_ref)^3)");
  v.param("flush_factor", flush_factor, "1", "F: scenario flushing factor");
  v.param("flush_drop_depth_mm", flush_drop_depth_mm, "mm", "scenario: F drops beyond depth");
  v.param("flush_drop_factor", flush_drop_factor, "1", "scenario: F x this beyond that depth");
  v.param("near_tip_zone_mm", near_tip_zone_mm, "mm", "l_z: side zone near the tip");
  v.param("jump_dz_mm", jump_dz_mm, "mm", "a retract longer than this is a jump");
  v.param("jump_eps", jump_eps, "1", "a jump multiplies c by (1 - jump_eps)");
  v.param("wall_sparks", wall_sparks, "", "tube: wall bins compete with the front (orbit)");
  v.param("axis_wn_rad_s", axis_wn_rad_s, "rad/s", "position loop natural frequency");
  v.param("axis_zeta", axis_zeta, "1", "position loop damping");
  v.param("v_max_mm_s", v_max_mm_s, "mm/s", "feed speed limit (toward the work, x, y)");
  v.param("v_jump_mm_s", v_jump_mm_s, "mm/s", "retract speed limit (z away from the work)");
  v.param("a_max_mm_s2", a_max_mm_s2, "mm/s2", "acceleration limit");
  v.param("encoder_um", encoder_um, "um", "encoder quantum of reported positions");
  v.param("servo_gain_mm_s_per_v", servo_gain_mm_s_per_v, "mm/s/V",
          "machine servo gain k: vz += -k (U_av - servo_ref_v) while servo_ref_v > 0; 0 = none");
  v.param("axis_step_us", axis_step_us, "us", "axis integration sub-step");
  v.param("wire_thickness_profile", wire_thickness_profile, "mm:mm", "cut length:thickness,...");
  v.param("wire_hole_from_mm", wire_hole_from_mm, "mm", "internal hole starts at this length");
  v.param("wire_hole_to_mm", wire_hole_to_mm, "mm", "internal hole ends at this length");
  v.param("wire_ibk_ref_a", wire_ibk_ref_a, "A", "break current I_BK at H = 10 mm, f = 1");
  v.param("wire_flush_floor", wire_flush_floor, "1", "f = floor + (1 - floor) F_eff");
  v.param("wire_break_current_ms", wire_break_current_ms, "ms", "break after mean I > I_BK this");
  v.param("wire_break_rab", wire_break_rab, "1", "rupture hazard: at this Rab ...");
  v.param("wire_break_rab_ms", wire_break_rab_ms, "ms", "... the mean time to break is this");
  v.param("wire_break_rab_width", wire_break_rab_width, "1", "hazard x e per this Rab above");
  v.param("wire_break_rab_tau_ms", wire_break_rab_tau_ms, "ms", "hazard acts on Rab lagged by");
  v.param("wire_break_rab_shape", wire_break_rab_shape, "1",
          "k: tolerated damage ~ Gamma(k, 1/k), integer 1..64");
  v.param("wire_kerf_debris_per_mm", wire_kerf_debris_per_mm, "1/mm",
          "kerf debris c_k added per mm of cut (0 = no kerf debris)");
  v.param("wire_kerf_flush_s", wire_kerf_flush_s, "s", "tau_k of the kerf debris at H = 10 mm");
  v.param("wire_kerf_flush_exp", wire_kerf_flush_exp, "1", "tau_k grows as (H/10 mm)^this");
  v.param("wire_nozzle_radius_mm", wire_nozzle_radius_mm, "mm", "flushing nozzle radius");
  v.param("wire_hole_flush_factor", wire_hole_flush_factor, "1",
          "F_eff x this while the nozzle overlaps the internal hole");
  v.param("wire_cavity_from_mm", wire_cavity_from_mm, "mm",
          "internal cavity starts at this length");
  v.param("wire_cavity_to_mm", wire_cavity_to_mm, "mm", "internal cavity ends (far wall) here");
  v.param("wire_cavity_height_mm", wire_cavity_height_mm, "mm",
          "void height of the cavity, centred in H (< H over the cavity)");
  v.param("wire_cavity_flush_factor", wire_cavity_flush_factor, "1",
          "flush of the wire's centre part at the cavity's far wall");
  v.param("wire_cavity_flush_mm", wire_cavity_flush_mm, "mm",
          "that flush loss fades e-fold per this much cut past the far wall");
  v.param("wire_cavity_debris", wire_cavity_debris, "1",
          "debris of the cavity's stagnant dielectric, met at the far wall (0..1)");
  v.param("mean_current_ema_ms", mean_current_ema_ms, "ms", "time constant of mean current");
  v.param("rab_window_ms", rab_window_ms, "ms", "Rab window");
  v.param("mean_voltage_tau_ms", mean_voltage_tau_ms, "ms", "U_av filter time constant");
  v.param("td_quantum_ns", td_quantum_ns, "ns", "Td quantisation (FPGA)");
  v.param("max_pulses_per_advance", max_pulses_per_advance, "1", "pulse budget per advance_to");
}

namespace {

// Collects (name, value) of the real fields so validate() can check finiteness of all of them.
class FiniteCheck final : public rt::ParamVisitor {
 public:
  explicit FiniteCheck(std::vector<rt::ParamError>& errs) : errs_(errs) {}

 protected:
  void on_param(std::string_view name, rt::ParamRef ref, rt::ParamInfo /*info*/) override {
    if (ref.type == rt::ParamType::kReal) {
      rt::require_finite(errs_, name, *static_cast<double*>(ref.field));
    }
  }

 private:
  std::vector<rt::ParamError>& errs_;
};

}  // namespace

std::vector<rt::ParamError> SimParams::validate() const {
  std::vector<rt::ParamError> e;
  FiniteCheck finite(e);
  const_cast<SimParams*>(this)->visit(finite);  // NOLINT: the visitor only reads
  using rt::require_non_negative;
  using rt::require_positive;
  using rt::require_range;
  for (auto [n, v] : {std::pair{"open_voltage_v", open_voltage_v},
                      {"discharge_voltage_v", discharge_voltage_v},
                      {"peak_current_a", peak_current_a},
                      {"default_on_time_us", default_on_time_us},
                      {"default_off_time_us", default_off_time_us},
                      {"default_arc_off_time_us", default_arc_off_time_us},
                      {"wait_time_us", wait_time_us},
                      {"td_tau_ref_us", td_tau_ref_us},
                      {"td_len_um", td_len_um},
                      {"td_quad_max_gap_um", td_quad_max_gap_um},
                      {"weibull_k", weibull_k},
                      {"deion_us", deion_us},
                      {"arc_gap_um", arc_gap_um},
                      {"debris_short_us", debris_short_us},
                      {"electrode_length_mm", electrode_length_mm},
                      {"flush_tau0_ms", flush_tau0_ms},
                      {"flush_depth_mm", flush_depth_mm},
                      {"flush_gap_ref_um", flush_gap_ref_um},
                      {"near_tip_zone_mm", near_tip_zone_mm},
                      {"jump_dz_mm", jump_dz_mm},
                      {"axis_wn_rad_s", axis_wn_rad_s},
                      {"axis_zeta", axis_zeta},
                      {"v_max_mm_s", v_max_mm_s},
                      {"v_jump_mm_s", v_jump_mm_s},
                      {"a_max_mm_s2", a_max_mm_s2},
                      {"wire_ibk_ref_a", wire_ibk_ref_a},
                      {"wire_break_current_ms", wire_break_current_ms},
                      {"wire_break_rab_ms", wire_break_rab_ms},
                      {"wire_break_rab_width", wire_break_rab_width},
                      {"wire_break_rab_tau_ms", wire_break_rab_tau_ms},
                      {"wire_kerf_flush_s", wire_kerf_flush_s},
                      {"mean_current_ema_ms", mean_current_ema_ms},
                      {"rab_window_ms", rab_window_ms},
                      {"mean_voltage_tau_ms", mean_voltage_tau_ms}}) {
    require_positive(e, n, v);
  }
  for (auto [n, v] : {std::pair{"arc_voltage_v", arc_voltage_v},
                      {"short_voltage_v", short_voltage_v},
                      {"td_tau_min_us", td_tau_min_us},
                      {"td_debris_k", td_debris_k},
                      {"arc_td_max_us", arc_td_max_us},
                      {"short_gap_um", short_gap_um},
                      {"debris_a_g_per_um", debris_a_g_per_um},
                      {"debris_k_s", debris_k_s},
                      {"arc_k_t", arc_k_t},
                      {"arc_k_c", arc_k_c},
                      {"arc_k_g", arc_k_g},
                      {"removal_mm3_per_j", removal_mm3_per_j},
                      {"crater_ref_um3", crater_ref_um3},
                      {"crater_exp", crater_exp},
                      {"removal_sigma", removal_sigma},
                      {"arc_removal_ratio", arc_removal_ratio},
                      {"arc_wear_factor", arc_wear_factor},
                      {"wear_ratio", wear_ratio},
                      {"wear_ratio_positive", wear_ratio_positive},
                      {"removal_scale_positive", removal_scale_positive},
                      {"work_thickness_mm", work_thickness_mm},
                      {"start_gap_um", start_gap_um},
                      {"initial_depth_mm", initial_depth_mm},
                      {"debris_kappa", debris_kappa},
                      {"debris_flush_k", debris_flush_k},
                      {"flush_drop_depth_mm", flush_drop_depth_mm},
                      {"flush_drop_factor", flush_drop_factor},
                      {"encoder_um", encoder_um},
                      {"servo_gain_mm_s_per_v", servo_gain_mm_s_per_v},
                      {"wire_hole_from_mm", wire_hole_from_mm},
                      {"wire_kerf_debris_per_mm", wire_kerf_debris_per_mm},
                      {"wire_kerf_flush_exp", wire_kerf_flush_exp},
                      {"wire_nozzle_radius_mm", wire_nozzle_radius_mm},
                      {"wire_cavity_from_mm", wire_cavity_from_mm},
                      {"wire_cavity_height_mm", wire_cavity_height_mm}}) {
    require_non_negative(e, n, v);
  }
  require_range(e, "debris_c0", debris_c0, 0.0, 1.0);
  require_range(e, "debris_c_max", debris_c_max, 0.0, 1.0);
  require_range(e, "arc_p0", arc_p0, 0.0, 1.0);
  require_range(e, "arc_p_max", arc_p_max, 0.0, 1.0);
  require_range(e, "flush_factor", flush_factor, 0.0, 1.0);
  require_range(e, "jump_eps", jump_eps, 0.0, 1.0);
  require_range(e, "wire_flush_floor", wire_flush_floor, 0.0, 1.0);
  require_range(e, "wire_break_rab", wire_break_rab, 0.0, 1.0);
  require_range(e, "wire_break_rab_shape", wire_break_rab_shape, 1.0,
                static_cast<double>(kMaxWireBreakShape));
  if (std::isfinite(wire_break_rab_shape) &&
      wire_break_rab_shape != std::floor(wire_break_rab_shape)) {
    e.push_back({"wire_break_rab_shape",
                 "must be a whole number (got " + std::to_string(wire_break_rab_shape) + ")"});
  }
  require_range(e, "wire_hole_flush_factor", wire_hole_flush_factor, 0.0, 1.0);
  require_range(e, "wire_cavity_flush_factor", wire_cavity_flush_factor, 0.0, 1.0);
  require_positive(e, "wire_cavity_flush_mm", wire_cavity_flush_mm);
  require_range(e, "wire_cavity_debris", wire_cavity_debris, 0.0, 1.0);
  require_range(e, "axis_step_us", axis_step_us, 1.0, 50.0);
  if (removal_mm3_per_j == 0.0 && crater_ref_um3 == 0.0) {
    e.push_back({"removal_mm3_per_j", "removal_mm3_per_j or crater_ref_um3 must be > 0"});
  }
  if (td_law != "exp" && td_law != "quadratic") {
    e.push_back({"td_law", "must be 'exp' or 'quadratic' (got '" + td_law + "')"});
  }
  if (tool_kind == "tube") {
    require_positive(e, "tool_od_mm", tool_od_mm);
    require_non_negative(e, "tool_id_mm", tool_id_mm);
    rt::require_ordered(e, "tool_id_mm", tool_id_mm, "tool_od_mm", tool_od_mm);
    if (!(hole_d_mm > tool_od_mm)) {
      e.push_back({"hole_d_mm", "must be > tool_od_mm (got " + std::to_string(hole_d_mm) +
                                    " <= " + std::to_string(tool_od_mm) + ")"});
    }
  } else if (tool_kind == "block") {
    require_positive(e, "tool_width_mm", tool_width_mm);
    require_positive(e, "tool_length_mm", tool_length_mm);
    require_positive(e, "side_gap_mm", side_gap_mm);
  } else if (tool_kind == "wire") {
    require_positive(e, "wire_d_mm", wire_d_mm);
    std::string why;
    const auto steps = parse_thickness_profile(wire_thickness_profile, &why);
    if (!steps) {
      e.push_back({"wire_thickness_profile", why});
    }
    rt::require_ordered(e, "wire_hole_from_mm", wire_hole_from_mm, "wire_hole_to_mm",
                        wire_hole_to_mm);
    rt::require_ordered(e, "wire_cavity_from_mm", wire_cavity_from_mm, "wire_cavity_to_mm",
                        wire_cavity_to_mm);
    if (steps && wire_cavity_to_mm > wire_cavity_from_mm && wire_cavity_height_mm > 0.0) {
      // The slabs above and below the cavity must keep some material: h_c < H(s) over it.
      double h_min = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < steps->size(); ++i) {
        const double next = i + 1 < steps->size() ? (*steps)[i + 1].from_mm
                                                  : std::numeric_limits<double>::infinity();
        if ((*steps)[i].from_mm < wire_cavity_to_mm && next > wire_cavity_from_mm) {
          h_min = std::min(h_min, (*steps)[i].thickness_mm);
        }
      }
      if (!(wire_cavity_height_mm < h_min)) {
        e.push_back({"wire_cavity_height_mm", "must be < the part thickness over the cavity (" +
                                                  std::to_string(h_min) + " mm; got " +
                                                  std::to_string(wire_cavity_height_mm) + ")"});
      }
    }
  } else {
    e.push_back({"tool_kind", "must be 'tube', 'block' or 'wire' (got '" + tool_kind + "')"});
  }
  if (td_quantum_ns < 1) e.push_back({"td_quantum_ns", "must be >= 1"});
  if (max_pulses_per_advance < 1) e.push_back({"max_pulses_per_advance", "must be >= 1"});
  return e;
}

}  // namespace edm::sim
