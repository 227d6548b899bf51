#pragma once
// Gain: out = k·in + offset.
//
// Non-finite policy (shared by the generic blocks): a NaN or ±Inf input, or a result that
// overflows, leaves `out` at its last value and update() returns kFault, so a broken sensor or
// wire never propagates NaN into control outputs and the task raises a block-fault alarm.
//
// RT-safe: update() (no allocation, no locks, noexcept). Not thread-safe: the owning task calls
// every member except the pins, which any thread may read (see pin.hpp).

#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct GainParams {
  double k{1.0};       // [out unit / in unit]
  double offset{0.0};  // [out unit]

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): a gain within ±1e6, an offset within ±1e12 (param_ranges.hpp).
    v.param("k", k, {"", "gain", ranges::kGain});
    v.param("offset", offset, {"", "added after the gain, in the output's unit", ranges::kSignal});
  }
};

class Gain final : public rt::BlockWithParams<GainParams> {
 public:
  /// RT-safe. kOk, or kFault (out held) on a non-finite input or result.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
};

}  // namespace edm::blocks
