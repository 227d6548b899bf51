#pragma once
// LowPass: first-order low-pass filter, discretised exactly for a zero-order-hold input.
//
//   α = 1 − exp(−dt/τ)          (computed as −expm1(−dt/τ): accurate when dt ≪ τ)
//   y ← y + α·(in − y);  out = y
//
// dt is the task period given to configure(). With the input held over each period, out after
// the update of cycle n equals the continuous filter's output at t = (n+1)·dt; a unit step from
// y = 0 gives out = 1 − exp(−(n+1)·dt/τ). α is recomputed on a runtime write of `tau` (RT-safe);
// the state y is kept, so the change is bumpless.
//
// A non-finite input leaves y and out unchanged and update() returns kFault.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct LowPassParams {
  rt::Duration tau{std::chrono::milliseconds(10)};  // time constant, > 0
  double initial{0.0};                              // y after activate() [signal unit]

  void visit(rt::ParamVisitor& v) {
    v.param("tau", tau, {"s", "time constant", ranges::kPositiveProcessTimeS});
    v.param("initial", initial,
            {"", "output after activation, in the signal's unit", ranges::kSignal});
  }
};

class LowPass final : public rt::BlockWithParams<LowPassParams> {
 public:
  /// Non-RT. Needs a task period > 0; computes α.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. y = out = initial.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (state and out held) on a non-finite input.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  /// The smoothing coefficient in use (tests, diagnostics). Owning thread only.
  [[nodiscard]] double alpha() const noexcept { return alpha_; }

 protected:
  void params_changed() noexcept override;

 private:
  void compute_alpha() noexcept;

  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
  rt::Duration period_{};
  double alpha_{1.0};
  double y_{0.0};
};

}  // namespace edm::blocks
