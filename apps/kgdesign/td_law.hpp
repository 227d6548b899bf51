#pragma once
// The ignition-delay law that the Kg design linearises: the simulator's own median
// τ_med(g, c) (sim::GapModel::td_median_us, PLANT-MODEL §6.2 step 4) for a preset's parameters at
// a fixed debris level, and its slope kd = dτ_med/dg, found by differentiating that function
// numerically. There is no second copy of the law here, so the design follows whatever law the
// simulator runs (the exp law of drill and sink, or the wire preset's quadratic law).
//
// Non-RT: each call builds a sim::GapModel (allocates). Thread-safe: pure functions on values.

#include <string>
#include <vector>

#include "edm/sim/params.hpp"

namespace edm::kgdesign {

struct TdMedianLaw {
  sim::SimParams params{};  // the simulator's parameters (the member defaults are DRILL)
  double debris{0.0};       // debris concentration c ∈ [0, 1] at the working point [–]

  /// The simulator's DRILL preset (exp law: g_r 20 µm, τ_r 5 µs, ℓ_g 7 µm, τ_min 0.5 µs, k_cd 2).
  [[nodiscard]] static TdMedianLaw drill();
  /// The simulator's SINK preset (exp law: g_r 50 µm, τ_r 10 µs, ℓ_g 15 µm, τ_min 1 µs, k_cd 2).
  [[nodiscard]] static TdMedianLaw sink();
  /// The simulator's own checks of params, and c ∈ [0, 1]. Empty means valid.
  [[nodiscard]] std::vector<std::string> validate() const;
};

/// τ_med at gap_um [µs]: sim::GapModel(law.params).td_median_us(gap_um, law.debris).
[[nodiscard]] double td_median_us(const TdMedianLaw& law, double gap_um);

/// Step of the difference quotient in td_gap_slope_us_per_um [µm].
inline constexpr double kSlopeStepUm = 0.01;

/// kd = dτ_med/dg at gap_um [µs/µm]: the five-point central difference of td_median_us with step
/// kSlopeStepUm (error O(h⁴): relative ≤ 3e-12 on the presets' exp laws for g 2…80 µm, exact
/// to rounding on a quadratic). The law must be smooth within ±2·kSlopeStepUm of gap_um: not at the
/// quadratic law's vertex or no-ignition cut-off (there the result is meaningless or not finite).
[[nodiscard]] double td_gap_slope_us_per_um(const TdMedianLaw& law, double gap_um);

}  // namespace edm::kgdesign
