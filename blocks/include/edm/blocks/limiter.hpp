#pragma once
// Limiter: clamps a signal to [min, max] and optionally limits its slew rate (limiter and ramp
// in one block).
//
//   target = clamp(in, min, max)
//   y      = target                                   first cycle after activate(), or rate = 0
//   y      = y_prev + clamp(target − y_prev, −rate·dt, +rate·dt)   otherwise
//   y      = clamp(y, min, max)      (the range wins when min/max change at run time)
//   out = y;  limited = (target ≠ in) or (y ≠ target)
//
// A step that fits within rate·dt lands exactly on target (no rounding residue). dt is the task
// period given to configure(). The first cycle after activate() starts from the input (clamped)
// rather than from an arbitrary 0.
//
// Status: kSaturated whenever `limited` is true, else kOk; a non-finite input leaves out,
// limited and the slew state unchanged and returns kFault.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct LimiterParams {
  double min{-1.0e9};  // [signal unit]
  double max{1.0e9};   // [signal unit], ≥ min
  double rate{0.0};    // [signal unit / s], ≥ 0; 0 = no slew-rate limit

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): a signal within ±1e12 (param_ranges.hpp: the ±1e9 defaults are "no
    // limit").
    v.param("min", min, {"", "lower limit, in the signal's unit", ranges::kSignal});
    v.param("max", max, {"", "upper limit, >= min, in the signal's unit", ranges::kSignal});
    v.param(
        "rate", rate,
        {"1/s", "slew-rate limit in signal units per second (0 = unlimited)", ranges::kSignalRate});
  }
  /// Cross-field rule: min <= max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class Limiter final : public rt::BlockWithParams<LimiterParams> {
 public:
  /// Non-RT. Needs a task period > 0 (for the slew-rate step).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Forgets the previous output: the next cycle starts from the input.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (clamped or rate-limited), or kFault (non-finite input).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 protected:
  void params_changed() noexcept override;

 private:
  void compute_step() noexcept;

  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
  rt::Output<bool> limited_{pins_, "limited"};
  double dt_s_{0.0};
  double max_step_{0.0};  // rate·dt [signal unit per cycle]; 0 = unlimited
  double y_{0.0};
  bool has_prev_{false};
};

}  // namespace edm::blocks
