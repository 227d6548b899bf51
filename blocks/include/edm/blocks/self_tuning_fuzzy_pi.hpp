#pragma once
// SelfTuningFuzzyPI: the gain self-tuning PI-type fuzzy controller of seed 000 (Lee & Liao 2003,
// §3.3, eq. 3-9, Tables 3 and 5) that holds the abnormal ratio Rab of a wire-EDM at its set point
// by acting on the arc-off time u and the servo reference voltage v.
//
//   e(k)  = Rab_ref − Rab_p(k)                      ce(k) = Rab_p(k−1) − Rab_p(k)   (0 at start)
//   E     = Ge·e,   CE = Gce·ce                                                  (eq. 3a, 3b)
//   dU    = height defuzzification of the 7 × 7 rule base of Table 3,
//           rule (E is A_i, CE is A_j) → dU is A_clamp(−(i+j), −3, 3),  i, j = −3…+3 (NB…PB)
//           = Σ w_ij·clamp(−(i+j)) / Σ w_ij,   w_ij = min(μ_i(E), μ_j(CE))
//   Φ     = g1 + g2·f(CE, 5E),  g1 = (1+α)/2, g2 = (1−α)/2, f(x, a) = (1 − e^(−a·x))/(1 + e^(−a·x))
//   Ψ     = max(psi_min, ol·(1 + dpf_gain·d_pf))  if e < overload_error, else 1            (eq. 8)
//           d_pf = Rab_p − Rab_f
//   Gu    = Ku·|e|·Φ·Ψ,   Gv = Kv·|e|·Φ·Ψ                                           (eq. 6a, 6b)
//   u(k)  = clamp(u(k−1) + dU·Gu, u_min_us, u_max_us)                           (eq. 4a, 5a)
//   v(k)  = clamp(v(k−1) + dU·Gv, v_min_v, v_max_v)                             (eq. 4b, 5b)
//
// Raising u or v lowers Rab (paper, Figs. 2-3): Rab above the set point gives e < 0, dU > 0, and
// both actuators rise. Φ → 1 when E and CE have the same sign (the error grows) and → α when they
// differ (approaching the set point: overshoot attenuation). Ψ boosts the action in overload.
//
// Choices where the paper is silent or garbled (see docs/controllers.md):
// - Terms (Fig. 6 is not legible): seven triangles with peaks at −3…+3 and half-width 1 on E, CE
//   and dU; E and CE beyond ±3 saturate to the outer terms (NB/PB shoulders). At term peaks dU is
//   exactly the table value; between them it interpolates.
// - Table 3 is read back as dU = clamp(−(E + CE)) (SEEDS.md; the extracted table has a missing
//   cell in column PS and agrees with the formula elsewhere).
// - Eq. (8) reads "e < 0.01": the default of `overload_error` is the paper's 0.01, so Ψ also
//   acts in the band −0.01 ≤ e < 0.01 around the set point. (SEEDS.md's digest wrote e < −0.01,
//   the default until issue 20; −0.01 remains a setting, see docs/controllers.md.)
// - Ψ is floored at psi_min (default 0): ol·(1 + 100·d_pf) turns negative for d_pf < −0.01 and
//   would reverse the action; the floor only prevents that reversal. psi_min = −1e9 leaves eq. 8
//   unfloored, as printed (B6 measures both).
// - Units: u in µs and v in V (Table 1: 9…50 µs, 30…70 V); Ku in µs and Kv in V per unit of
//   dU·|e|. The initial u and v (Table 4 is not legible) are parameters.
// - Rab_ref: the input rab_ref when > 0, else the parameter rab_ref_default.
// - Rab_p and Rab_f are clamped to [0, 1] (Rab is a ratio) before use: a grey prediction far
//   outside it (start-up transients) would otherwise multiply the gain through |e| and Ψ.
// - Start-up: the Butterworth filter and the grey predictor need ~5/(0.7·π·Wn) samples to settle
//   (≈ 190 at Wn = 0.012); during that transient the prediction is wild and the overload factor
//   Ψ drives u and v to their limits. settle_samples (default 0, as in the paper) holds u and v
//   for that many samples after activate() while Rab_p is tracked.
// - enable = false holds u and v (and remembers Rab_p, so re-enabling does not see a jump in ce).
// - The paper samples every 40 ms: run the block on a 40 ms task (Ge, Gce, Ku, Kv are per sample).
//
// Status: kSaturated when an actuator clamp cut the step, else kOk. A non-finite input holds the
// outputs and returns kFault.
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct SelfTuningFuzzyPIParams {
  double ge{5.0};               // Ge [1/Rab], Table 5
  double gce{40.0};             // Gce [1/Rab], Table 5
  double alpha{0.7};            // α in (0, 1], Table 5
  double ol{2.0};               // overloading parameter, Table 5
  double ku{0.06};              // Ku [µs], Table 5 case 1
  double kv{0.03};              // Kv [V], Table 5 case 1
  double rab_ref_default{0.6};  // Rab_ref in (0, 1] while the rab_ref input is 0, Table 5 case 1
  double overload_error{0.01};  // Ψ applies when e < this (eq. 8 as printed: 0.01)
  double dpf_gain{100.0};       // the 100 of eq. 8
  double psi_min{0.0};          // floor of Ψ in overload (−1e9: none, eq. 8 as printed)
  double u_min_us{9.0};         // arc-off time range, Table 1 [µs]
  double u_max_us{50.0};
  double u_initial_us{20.0};  // arc-off time after activate() [µs]
  double v_min_v{30.0};       // servo reference voltage range, Table 1 [V]
  double v_max_v{70.0};
  double v_initial_v{40.0};        // servo reference voltage after activate() [V]
  std::int64_t settle_samples{0};  // hold u, v for this many samples after activate()

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31), seed 000 Table 5 and Table 1: Ge 5 and Gce 40 (up to 1e4), ol 2-3 (up to
    // 100), Ku 0.06-0.08 µs and Kv 0.03-0.16 V (up to 1000), the d_pf gain 100 (up to 1e4), the
    // arc-off time 9-50 µs (within 10 ms) and the servo reference 30-70 V (within 400 V); psi_min
    // down to -1e9, the documented "no floor".
    v.param("ge", ge, {"1", "error scaling Ge", rt::open_closed(0.0, 1.0e4)});
    v.param("gce", gce, {"1", "change-of-error scaling Gce", rt::open_closed(0.0, 1.0e4)});
    v.param("alpha", alpha, {"1", "overshoot attenuation alpha", rt::closed(1e-9, 1.0)});
    v.param("ol", ol, {"1", "overloading parameter ol", rt::open_closed(0.0, 100.0)});
    v.param("ku", ku, {"us", "global gain of the arc-off time", rt::closed(0.0, 1000.0)});
    v.param("kv", kv, {"V", "global gain of the servo reference voltage", rt::closed(0.0, 1000.0)});
    v.param("rab_ref_default", rab_ref_default,
            {"1", "Rab set point while rab_ref is 0", rt::closed(1e-9, 1.0)});
    v.param("overload_error", overload_error,
            {"1", "Psi applies when e is below this (eq. 8: 0.01)", rt::closed(-1.0, 1.0)});
    v.param("dpf_gain", dpf_gain,
            {"1", "gain on d_pf = Rab_p - Rab_f in Psi", rt::closed(0.0, 1.0e4)});
    v.param("psi_min", psi_min,
            {"1", "floor of Psi in overload (0: no reversal; -1e9: none, eq. 8 as printed)",
             rt::closed(-1.0e9, 100.0)});
    v.param("u_min_us", u_min_us, {"us", "shortest arc-off time", ranges::kPulseUs});
    v.param("u_max_us", u_max_us, {"us", "longest arc-off time, >= u_min_us", ranges::kPulseUs});
    v.param("u_initial_us", u_initial_us,
            {"us", "arc-off time after activation, in [u_min_us, u_max_us]", ranges::kPulseUs});
    v.param("v_min_v", v_min_v, {"V", "lowest servo reference voltage", ranges::kVoltageV});
    v.param("v_max_v", v_max_v,
            {"V", "highest servo reference voltage, >= v_min_v", ranges::kVoltageV});
    v.param("v_initial_v", v_initial_v,
            {"V", "servo reference voltage after activation, in [v_min_v, v_max_v]",
             ranges::kVoltageV});
    v.param("settle_samples", settle_samples,
            {"samples",
             "hold u and v this many samples after activation while filter and predictor settle",
             rt::closed(0.0, 1e9)});
  }
  /// Cross-field rules: u_min_us <= u_initial_us <= u_max_us, v_min_v <= v_initial_v <= v_max_v.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class SelfTuningFuzzyPI final : public rt::BlockWithParams<SelfTuningFuzzyPIParams> {
 public:
  /// Crisp dU of the rule base for E and CE (height defuzzification, see above). Pure, RT-safe.
  static double rule_output(double e_scaled, double ce_scaled) noexcept;
  /// Non-RT. u = u_initial_us, v = v_initial_v (clamped), du = 0, phi = psi = 1.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (an actuator limit cut the step) or kFault (non-finite input).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  rt::Input<double> rab_p_{pins_, "rab_p", "1"};
  rt::Input<double> rab_f_{pins_, "rab_f", "1"};
  rt::Input<double> rab_ref_{pins_, "rab_ref", "1"};
  rt::Input<double> track_u_{pins_, "track_arc_off_time_us", "us"};
  rt::Input<double> track_v_{pins_, "track_servo_ref_v",
                             "V"};  // bumpless transfer: the commands applied while idle
  rt::Input<bool> enable_{pins_, "enable", "", true};
  rt::Output<double> arc_off_time_us_{pins_, "arc_off_time_us", "us"};
  rt::Output<double> servo_ref_v_{pins_, "servo_ref_v", "V"};
  rt::Output<double> du_{pins_, "du", "1"};
  rt::Output<double> phi_{pins_, "phi", "1"};
  rt::Output<double> psi_{pins_, "psi", "1"};
  rt::Output<double> error_{pins_, "error", "1"};
  rt::Output<bool> saturated_{pins_, "saturated"};
  double u_{0.0};
  double v_{0.0};
  double prev_p_{0.0};
  bool have_prev_{false};
  std::int64_t samples_{0};  // samples since activate(), saturating at settle_samples
};

}  // namespace edm::blocks
