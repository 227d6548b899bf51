#pragma once
// SelfTuningRegulator: the two decoupled minimum-variance self-tuning loops of seed 001 (Wang, Wu
// & Liu, adaptive control of die-sinking EDM) on the five gap-state ratios.
//
// Controlled variables, from the pulse-width ratios φ (open d, spark e, transient arc e', stable
// arc a, short s) and the period ratios Φ = K1·φ, K1 = ti/tp = ti/(ti + to):
//   y_v = φe + 2φe' + 2φa + 2φs        (0: Us too large, open; 2: Us too small, shorting; ~1 good)
//   y_t = Φe + 2Φe' + 2Φa              (~0: to too long; ~0.9 good)
// Models (zero-order, the paper's §4.1), k the sample index:
//   main       y_v(k+d+1) = β00·u_v(k) + β01·u_v(k−1) + β0c + ε_v     β00 = −1 fixed
//   auxiliary  y_t(k+1)   = β10·u_t(k) + β1c + ε_t                     β10 = −1/ti fixed
// β01, β0c (2 regressors) and β1c (1 regressor) are estimated by RLS with forgetting λ (0.97),
// rls_core.hpp. Minimum-variance law (J = E[y − y_r]², the model solved for the u that puts the
// prediction on the reference):
//   u_v(k) = (y_rv − β01·u_v(k−1) − β0c) / β00,    u_t(k) = (y_rt − β1c) / β10
// Reference decision (§3): gap good (φe' < transient_arc_limit and φa <= stable_arc_limit) →
// y_rv, y_rt approach y_rv_good (0.95), y_rt_good (0.9) by ref_rise of the distance per sample;
// a stable arc (φa > stable_arc_limit) → y_rv, y_rt fall by ref_step per sample (floors y_rv_min,
// y_rt_min) until φa returns to 0; transient arcs above the limit without a stable arc → hold.
// The inputs y_rv_ref / y_rt_ref override the decision while > 0.
// Decoupling gain (§3, k1_on_us): Us = K1·us_per_unit_v·u_v with K1 = ti/(ti + t_o) of the off time
// output with it, so that the gap-voltage servo's balance Ūg = Us, Ūg ≈ K1·U_e in a good gap,
// does not move when the auxiliary loop changes t_o (k1_on_us false: Us = us_per_unit_v·u_v).
// Loops in turn (§4, alternate): "分时交替" — sample k computes the main loop alone when
// k is even and the auxiliary loop alone when k is odd; the other loop holds its u, and the
// main model's sample index (its regressor history and d_v) counts main-loop samples only, and
// each reference decision (y_rv's, y_rt's) also runs on its own loop's samples
// (alternate false: both loops every sample).
//
// Choices where the paper is silent (docs/controllers.md):
// - u_v is in the paper's normalised D/A units (β00 = −1 because u_v ≈ 1.6 at full scale, like
//   y_v); the servo reference voltage is Us = us_per_unit_v·u_v [V]. u_t is the pulse-off time
//   in µs, so β10 = −1/ti with ti in µs.
// - φ comes from the simulator's five-state time ratios (ratio_*, the share of time spent in
//   pulses of each class; the sim charges each pulse's off time to its class, so with equal off
//   times this is the pulse-width ratio). Φ = K1·φ uses the off time commanded last sample.
// - The regressor history before activate() is the initial u (the outputs held there).
// - u_v and u_t are clamped to their ranges; the RLS sees the clamped values.
// Status: kSaturated when a clamp cut a control value (the last time its loop ran), kFault on a
// non-finite input (outputs held). RT-safe: update(). Not thread-safe: the owning task calls every
// member except the pins.

#include <array>
#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/rls_core.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct SelfTuningRegulatorParams {
  static constexpr std::int64_t kMaxDelay = 4;

  // Main loop: y_v → servo reference voltage.
  std::int64_t delay_v{1};     // d_v in samples (paper: 1 at T = 50 ms, 0 at T = 100 ms)
  double beta00{-1.0};         // fixed β00 (paper: −1)
  double us_per_unit_v{40.0};  // Us [V] per unit of u_v
  double u_v_min{0.25};        // range of u_v (normalised units)
  double u_v_max{2.0};
  double u_v_initial{1.0};
  double beta01_init{0.0};  // RLS start values
  double beta0c_init{2.0};  // y_v ≈ 1 at u_v = 1 with β01 = 0
  // Auxiliary loop: y_t → pulse-off time.
  double ti_us{100.0};    // pulse width ti [µs]: K1 = ti/(ti + to), β10 = −1/ti
  double to_min_us{5.0};  // range of the pulse-off time [µs]
  double to_max_us{500.0};
  double to_initial_us{50.0};
  double beta1c_init{1.0};
  // Estimation.
  double lambda{0.97};       // forgetting factor (paper: 0.97)
  double p0{100.0};          // initial covariance
  double trace_max{1000.0};  // covariance bound per estimator
  // Reference decision.
  double y_rv_good{0.95};
  double y_rt_good{0.9};
  double transient_arc_limit{0.1};  // φe' below this (and no stable arc): gap good
  double stable_arc_limit{0.0};     // φa above this: a stable arc
  double ref_rise{0.2};             // fraction of the distance to the good value per sample
  double ref_step{0.05};            // decrease per sample while a stable arc lasts
  double y_rv_min{0.3};
  double y_rt_min{0.3};
  // The paper's structure (both true as published).
  bool k1_on_us{true};   // Us = K1·us_per_unit_v·u_v (false: us_per_unit_v·u_v)
  bool alternate{true};  // the two loops computed in turn, one per sample (false: both)

  void visit(rt::ParamVisitor& v) {
    v.param("delay_v", delay_v,
            rt::load_time({"samples",
                           "prediction delay d_v of the main model (shapes the regressor history)",
                           rt::closed(0.0, static_cast<double>(kMaxDelay))}));
    // Ranges (issue 31), seed 001: beta00 = -1 (within ±1000), u_v a multiple of us_per_unit_v
    // (0-100; the reference voltage itself below 400 V), ti and to up to 10 ms (PM §1: t_on
    // 1-1000 µs), start values within ±1e6, the RLS covariance p0 up to 1e9 and its trace 1e12.
    v.param("beta00", beta00,
            {"1", "fixed beta00 of the main model, != 0 (paper -1)", rt::closed(-1000.0, 1000.0)});
    v.param("us_per_unit_v", us_per_unit_v,
            {"V", "servo reference voltage per unit of u_v", rt::open_closed(0.0, 400.0)});
    v.param("u_v_min", u_v_min, {"1", "lowest u_v", rt::closed(0.0, 100.0)});
    v.param("u_v_max", u_v_max, {"1", "highest u_v, >= u_v_min", rt::closed(0.0, 100.0)});
    v.param("u_v_initial", u_v_initial,
            {"1", "u_v after activation, in [u_v_min, u_v_max]", rt::closed(0.0, 100.0)});
    v.param("beta01_init", beta01_init, {"1", "initial estimate of beta01", ranges::kCoefficient});
    v.param("beta0c_init", beta0c_init, {"1", "initial estimate of beta0c", ranges::kCoefficient});
    v.param(
        "ti_us", ti_us,
        {"us", "pulse width ti: K1 = ti/(ti+to), beta10 = -1/ti", rt::open_closed(0.0, 10000.0)});
    v.param("to_min_us", to_min_us,
            {"us", "shortest pulse-off time", rt::open_closed(0.0, 10000.0)});
    v.param("to_max_us", to_max_us,
            {"us", "longest pulse-off time, >= to_min_us", ranges::kPulseUs});
    v.param("to_initial_us", to_initial_us,
            {"us", "pulse-off time after activation, in [to_min_us, to_max_us]", ranges::kPulseUs});
    v.param("beta1c_init", beta1c_init, {"1", "initial estimate of beta1c", ranges::kCoefficient});
    v.param("lambda", lambda, {"1", "RLS forgetting factor", rt::closed(0.5, 1.0)});
    v.param("p0", p0, {"1", "initial RLS covariance", rt::open_closed(0.0, 1.0e9)});
    v.param("trace_max", trace_max,
            {"1", "bound of the RLS covariance trace, >= 2*p0", rt::open_closed(0.0, 1.0e12)});
    v.param("y_rv_good", y_rv_good,
            {"1", "y_v reference in a good gap (paper 0.95)", rt::closed(0.0, 2.0)});
    v.param("y_rt_good", y_rt_good,
            {"1", "y_t reference in a good gap (paper 0.9)", rt::closed(0.0, 2.0)});
    v.param("transient_arc_limit", transient_arc_limit,
            {"1", "good gap: transient-arc ratio below", rt::closed(0.0, 1.0)});
    v.param("stable_arc_limit", stable_arc_limit,
            {"1", "stable arc: stable-arc ratio above this", rt::closed(0.0, 1.0)});
    v.param("ref_rise", ref_rise,
            {"1", "approach to the good references per sample", rt::closed(1e-9, 1.0)});
    v.param("ref_step", ref_step,
            {"1", "reference decrease per sample during a stable arc", rt::closed(0.0, 1.0)});
    v.param("y_rv_min", y_rv_min,
            {"1", "floor of the y_v reference, <= y_rv_good", rt::closed(0.0, 2.0)});
    v.param("y_rt_min", y_rt_min,
            {"1", "floor of the y_t reference, <= y_rt_good", rt::closed(0.0, 2.0)});
    v.param("k1_on_us", k1_on_us,
            rt::load_time({"", "decoupling gain K1 = ti/(ti+to) on Us (paper: true)"}));
    v.param("alternate", alternate,
            rt::load_time({"", "the two loops computed in turn, one per sample (paper: true)"}));
  }
  /// Rules a range cannot say: beta00 != 0, the min/initial/max orders, trace_max >= 2*p0.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class SelfTuningRegulator final : public rt::BlockWithParams<SelfTuningRegulatorParams> {
 public:
  /// Non-RT. u_v, u_t at their initial values (also as regressor history), RLS reset.
  void activate() noexcept override;
  /// RT-safe. One sample of both loops.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  void publish() noexcept;

  rt::Input<double> ratio_normal_{pins_, "ratio_normal", "1"};
  rt::Input<double> ratio_transient_arc_{pins_, "ratio_transient_arc", "1"};
  rt::Input<double> ratio_stable_arc_{pins_, "ratio_stable_arc", "1"};
  rt::Input<double> ratio_short_{pins_, "ratio_short", "1"};
  rt::Input<double> y_rv_ref_{pins_, "y_rv_ref", "1"};
  rt::Input<double> y_rt_ref_{pins_, "y_rt_ref", "1"};
  rt::Input<bool> enable_{pins_, "enable", "", true};
  rt::Output<double> servo_ref_v_{pins_, "servo_ref_v", "V"};
  rt::Output<double> off_time_us_{pins_, "off_time_us", "us"};
  rt::Output<double> u_v_out_{pins_, "u_v", "1"};
  rt::Output<double> y_v_out_{pins_, "y_v", "1"};
  rt::Output<double> y_t_out_{pins_, "y_t", "1"};
  rt::Output<double> y_rv_out_{pins_, "y_rv", "1"};
  rt::Output<double> y_rt_out_{pins_, "y_rt", "1"};
  rt::Output<double> beta01_{pins_, "beta01", "1"};
  rt::Output<double> beta0c_{pins_, "beta0c", "1"};
  rt::Output<double> beta1c_{pins_, "beta1c", "1"};
  rt::Output<double> k1_{pins_, "k1", "1"};
  rt::Output<bool> saturated_{pins_, "saturated"};
  RlsCore main_;
  RlsCore aux_;
  std::array<double, SelfTuningRegulatorParams::kMaxDelay + 2> hist_v_{};  // u_v(k−1−i)
  double u_t_{0.0};
  bool aux_turn_{false};  // alternate: this sample is the auxiliary loop's
  bool sat_v_{false};     // the clamp cut u_v when the main loop last ran
  bool sat_t_{false};     // the clamp cut t_o when the auxiliary loop last ran
  double y_rv_{0.0};
  double y_rt_{0.0};
};

}  // namespace edm::blocks
