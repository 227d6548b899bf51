#include "td_law.hpp"

#include "edm/sim/gap_model.hpp"

namespace edm::kgdesign {

TdMedianLaw TdMedianLaw::drill() { return {*sim::SimParams::preset("drill"), 0.0}; }

TdMedianLaw TdMedianLaw::sink() { return {*sim::SimParams::preset("sink"), 0.0}; }

std::vector<std::string> TdMedianLaw::validate() const {
  std::vector<std::string> errs;
  for (const auto& e : params.validate()) {
    errs.push_back(e.field.empty() ? e.message : e.field + " " + e.message);
  }
  if (!(debris >= 0.0 && debris <= 1.0)) errs.emplace_back("debris must be in [0, 1]");
  return errs;
}

double td_median_us(const TdMedianLaw& law, double gap_um) {
  return sim::GapModel(law.params).td_median_us(gap_um, law.debris);
}

double td_gap_slope_us_per_um(const TdMedianLaw& law, double gap_um) {
  const sim::GapModel model(law.params);
  const auto tau = [&](double g) { return model.td_median_us(g, law.debris); };
  const double h = kSlopeStepUm;
  // f' ≈ [f(g−2h) − 8 f(g−h) + 8 f(g+h) − f(g+2h)] / (12 h), truncation error h⁴ f⁽⁵⁾/30.
  return (tau(gap_um - 2.0 * h) - 8.0 * tau(gap_um - h) + 8.0 * tau(gap_um + h) -
          tau(gap_um + 2.0 * h)) /
         (12.0 * h);
}

}  // namespace edm::kgdesign
