#pragma once
// Select: IEC 61131-3 SEL with a bumpless transfer — the switch between two controllers (or a
// controller and fixed settings) while the machine runs.
//
//   s   = g OR select                     (g: a wired condition; select: the operator's parameter,
//                                          writable at run time with var.write)
//   src = s ? in1 : in0
//   on a change of s at cycle k:  b = out(k−1) − src(k)      (the bump the switch would make)
//   out = src + b·max(0, 1 − (t − t_k)/ramp_time)            (b decays linearly to 0)
//   active0 = !s, active1 = s, transferring = (the ramp has not ended)
//
// ramp_time = 0 switches at once. A source that tracks the applied command (SelfTuningFuzzyPI's
// track inputs, wired to `out`, with `enable` wired to active0/1) has no bump to ramp away; the
// ramp is for sources that cannot track (fixed settings, a constant). activate() already sets
// the outputs from g OR select (blocks ahead are activated first, so a g wired to another
// Select's active1 is set), so readers ahead in the program or in other tasks never see 0; the
// first cycle after activate() takes the selected input as is. A switch during a
// ramp starts a new ramp from the current output. Wire `active0`/`active1` to the controllers'
// `enable` inputs, and a second Select's `g` to `active1` to switch two channels together.
//
// A non-finite selected input leaves every output unchanged and update() returns kFault.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct SelectParams {
  bool select{false};                            // selects in1 (OR-ed with the input g)
  rt::Duration ramp_time{rt::Duration::zero()};  // bump decay time after a switch, ≥ 0

  void visit(rt::ParamVisitor& v) {
    v.param("select", select,
            {"", "true selects in1 (OR-ed with the input g); writable at run time"});
    v.param(
        "ramp_time", ramp_time,
        {"s", "after a switch, the output's step decays linearly to 0 over this time (0 = at once)",
         ranges::kProcessTimeS});
  }
};

class Select final : public rt::BlockWithParams<SelectParams> {
 public:
  /// Non-RT. Needs a task period > 0 (for the ramp).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. The next cycle takes the selected input as is; active0/1 show `select` until then.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (non-finite selected input).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  rt::Input<bool> g_{pins_, "g"};
  rt::Input<double> in0_{pins_, "in0"};
  rt::Input<double> in1_{pins_, "in1"};
  rt::Output<double> out_{pins_, "out"};
  rt::Output<bool> active0_{pins_, "active0"};
  rt::Output<bool> active1_{pins_, "active1"};
  rt::Output<bool> transferring_{pins_, "transferring"};
  double dt_s_{0.0};
  bool has_prev_{false};
  bool sel_{false};
  double bump_{0.0};         // b: out − src at the switch
  double ramp_left_s_{0.0};  // time left in the ramp
  double ramp_total_s_{0.0};
};

}  // namespace edm::blocks
