#pragma once
// PolaritySwitch: reverses the generator polarity only while the generator is off (seed 004:
// drill with negative polarity, finish the wall with positive polarity).
//
// When request_positive differs from the current polarity:
//   1. generator_on = false at once (switching = true);
//   2. once generator_on has been false for `settle` (measured on the cycles' release times from
//      the first cycle that output false), polarity_positive takes the request;
//   3. generator_on stays false for another `settle` after the switch, then follows
//      generator_on_request again (switching = false).
// If the generator was already off for `settle` when the request changes, step 2 happens in the
// same cycle. If the request returns to the current polarity before step 2, nothing is switched
// and generator_on follows its request at once. A new switch also waits `settle` after the
// previous one (no relay chatter). After activate() the polarity output is treated as just
// switched: the generator stays off for the first `settle`.
//
// Invariant (tested): polarity_positive never changes in a cycle in which, or within `settle`
// after a cycle in which, generator_on was true; generator_on is never true within `settle` after
// a change of polarity_positive.
//
// Status: always kOk (BOOL inputs only).
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins (see
// pin.hpp).

#include <chrono>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct PolaritySwitchParams {
  rt::Duration settle{std::chrono::milliseconds(20)};  // > 0, generator off before/after a switch
  bool initial_positive{false};  // polarity after activate(); false = negative (drilling)

  void visit(rt::ParamVisitor& v) {
    v.param("settle", settle,
            {"s", "generator-off time before and after a switch", ranges::kPositiveSettleS});
    v.param("initial_positive", initial_positive,
            {"", "polarity after activation (false: negative, electrode -)"});
  }
};

class PolaritySwitch final : public rt::BlockWithParams<PolaritySwitchParams> {
 public:
  /// Non-RT. polarity_positive = initial_positive, generator off, switching = true until the
  /// first `settle` has passed.
  void activate() noexcept override;
  /// RT-safe. Always kOk.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<bool> request_positive{pins_, "request_positive"};
  rt::Input<bool> generator_on_request{pins_, "generator_on_request"};
  rt::Output<bool> polarity_positive{pins_, "polarity_positive"};
  rt::Output<bool> generator_on{pins_, "generator_on"};
  rt::Output<bool> switching{pins_, "switching"};

 private:
  bool polarity_{false};         // polarity_positive as last output
  bool gen_on_{false};           // generator_on as last output
  rt::TimePoint off_since_{};    // release of the first cycle of the current generator-off run
  rt::TimePoint last_switch_{};  // release of the cycle that last changed the polarity
  bool started_{false};          // the first cycle after activate() has run (times are set)
};

}  // namespace edm::blocks
