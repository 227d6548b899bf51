#pragma once
// RecursiveLeastSquares: on-line estimation of θ in y(k) = φ(k)ᵀ·θ + ε(k) with a forgetting
// factor and a covariance bound, as seed 001 (Wang, Wu & Liu) uses to estimate β01, β0c and β1c
// of its die-sinking gap models (λ = 0.97). Equations in rls_core.hpp and docs/controllers.md.
//
// Pins: y and the regressors phi0…phi3 (the first n_params are used; phi1… default to 0, so a
// constant regressor is written `phi1: 1.0` in YAML); enable (false: estimates held). Outputs
// theta0…theta3, error (a-priori y − φᵀθ), y_hat (a-priori φᵀθ), trace_p (tr P) and bounded
// (the trace bound acted this cycle).
// Status: kSaturated while the trace bound acts, kFault on a non-finite input or result (θ and P
// are kept), else kOk.
// RT-safe: update() (fixed-size storage, no allocation). Not thread-safe: the owning task calls
// every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/rls_core.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct RecursiveLeastSquaresParams {
  std::int64_t n_params{2};  // regressors used, 1..4
  double lambda{0.97};       // forgetting factor in [0.001, 1] (seed 001: 0.97)
  double p0{1000.0};         // initial covariance P = p0·I (> 0)
  double trace_max{1e4};     // bound on tr P (>= n_params·p0 is the usual choice)
  double theta0_init{0.0};   // θ after activate()
  double theta1_init{0.0};
  double theta2_init{0.0};
  double theta3_init{0.0};

  void visit(rt::ParamVisitor& v) {
    v.param("n_params", n_params,
            rt::load_time({"1", "number of regressors phi0.. used (the estimate's dimension)",
                           rt::closed(1.0, static_cast<double>(RlsCore::kMaxParams))}));
    v.param("lambda", lambda, {"1", "forgetting factor", rt::closed(1e-3, 1.0)});
    // Ranges (issue 31): the covariance start p0 up to 1e9 and its trace bound 1e12 (the defaults
    // 1e3 and 1e4), start values within ±1e6 (param_ranges.hpp).
    v.param("p0", p0, {"1", "initial covariance P = p0*I", rt::open_closed(0.0, 1.0e9)});
    v.param("trace_max", trace_max,
            {"1", "upper bound of trace(P), >= p0", rt::open_closed(0.0, 1.0e12)});
    v.param("theta0_init", theta0_init, {"", "initial estimate of theta0", ranges::kCoefficient});
    v.param("theta1_init", theta1_init, {"", "initial estimate of theta1", ranges::kCoefficient});
    v.param("theta2_init", theta2_init, {"", "initial estimate of theta2", ranges::kCoefficient});
    v.param("theta3_init", theta3_init, {"", "initial estimate of theta3", ranges::kCoefficient});
  }
  /// Cross-field rule: trace_max >= p0.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class RecursiveLeastSquares final : public rt::BlockWithParams<RecursiveLeastSquaresParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override;
  /// Non-RT. θ = theta*_init, P = p0·I.
  void activate() noexcept override;
  /// RT-safe. One RLS step with the current y and φ.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  [[nodiscard]] const RlsCore& core() const noexcept { return rls_; }

 private:
  rt::Input<double> y_;
  rt::Input<double> phi_[RlsCore::kMaxParams];
  rt::Input<bool> enable_{true};
  rt::Output<double> theta_[RlsCore::kMaxParams];
  rt::Output<double> error_, y_hat_, trace_p_;
  rt::Output<bool> bounded_;
  RlsCore rls_;
};

}  // namespace edm::blocks
