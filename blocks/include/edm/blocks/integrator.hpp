#pragma once
// Integrator: out ← clamp(out + k·in·dt, min, max), with a level-triggered reset.
//
//   reset = true:  out = clamp(initial, min, max)                       (in is not read)
//   otherwise:     out = clamp(out + k·in·dt, min, max)   (forward Euler; anti-windup by clamping)
//
// The state is the output pin itself: every cycle starts from out.get(). So a value written
// into `out` from outside (a retained value restored at start-up, or a forced value) is where
// integration continues, and unforcing is bumpless. configure() sets out to
// clamp(initial, min, max); activate() leaves out alone so that a restored value survives it.
// dt is the task period given to configure().
//
// Status: kSaturated when the clamp cut the step (pushing into a limit), else kOk. A non-finite
// input holds out and returns kFault; a non-finite state (e.g. a corrupt restored value) is
// replaced by clamp(initial, min, max) and returns kFault.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct IntegratorParams {
  double k{1.0};        // [out unit / (in unit · s)]
  double min{-1.0e9};   // [out unit]
  double max{1.0e9};    // [out unit], ≥ min
  double initial{0.0};  // [out unit], used clamped to [min, max]

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): a gain within ±1e6, signals within ±1e12 (param_ranges.hpp).
    v.param("k", k, {"1/s", "integration gain: out changes by k·in per second", ranges::kGain});
    v.param("min", min, {"", "lower limit of out", ranges::kSignal});
    v.param("max", max, {"", "upper limit of out, >= min", ranges::kSignal});
    v.param("initial", initial,
            {"", "out at configure and while reset is true (clamped)", ranges::kSignal});
  }
  /// Cross-field rule: min <= max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class Integrator final : public rt::BlockWithParams<IntegratorParams> {
 public:
  /// Non-RT. Needs a task period > 0. Sets out = clamp(initial, min, max).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// RT-safe. kOk, kSaturated (clamped) or kFault (non-finite input or state).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 protected:
  void params_changed() noexcept override;

 private:
  void compute_gain() noexcept;
  [[nodiscard]] double reset_value() const noexcept;

  rt::Input<double> in_{pins_, "in"};
  rt::Input<bool> reset_{pins_, "reset"};
  rt::Output<double> out_{pins_, "out"};
  double dt_s_{0.0};
  double k_dt_{0.0};  // k·dt [out unit / in unit]
};

}  // namespace edm::blocks
