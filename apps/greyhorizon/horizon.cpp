// The offline horizon choice: see horizon.hpp.

#include "horizon.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "edm/blocks/butterworth_low_pass.hpp"
#include "edm/blocks/grey_predictor_gm11.hpp"

namespace edm::greyhorizon {

double butterworth_dc_delay(double wn) {
  constexpr double kPi = 3.14159265358979323846;
  return 1.0 / (std::sqrt(2.0) * std::tan(kPi * wn / 2.0));
}

std::vector<double> butterworth_filter(const std::vector<double>& x, double wn) {
  const auto c = blocks::ButterworthLowPass::design(wn);
  std::vector<double> y(x.size());
  if (x.empty()) {
    return y;
  }
  double x1 = x[0], x2 = x[0], y1 = x[0], y2 = x[0];
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double v = c.b0 * x[k] + c.b1 * x1 + c.b2 * x2 - c.a1 * y1 - c.a2 * y2;
    x2 = x1;
    x1 = x[k];
    y2 = y1;
    y1 = v;
    y[k] = v;
  }
  return y;
}

std::vector<double> shifted_moving_average(const std::vector<double>& x, std::size_t length,
                                           std::size_t shift) {
  std::vector<double> o(x.size(), std::numeric_limits<double>::quiet_NaN());
  if (length == 0) {
    return o;
  }
  // Prefix sums: window of x(k−L+1+s … k+s) is [k + s + 1 − L, k + s].
  std::vector<double> prefix(x.size() + 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    prefix[i + 1] = prefix[i] + x[i];
  }
  for (std::size_t k = 0; k < x.size(); ++k) {
    const std::size_t hi = k + shift;  // inclusive
    if (hi >= x.size() || hi + 1 < length) {
      continue;
    }
    const std::size_t lo = hi + 1 - length;
    o[k] = (prefix[hi + 1] - prefix[lo]) / static_cast<double>(length);
  }
  return o;
}

HorizonResult choose_horizon(const std::vector<double>& x, double wn, const HorizonOptions& opt) {
  if (opt.window < 2) {
    throw std::invalid_argument("choose_horizon: window must be at least 2");
  }
  const std::vector<double> f = butterworth_filter(x, wn);
  const std::vector<double> o = shifted_moving_average(x, opt.ma_length, opt.ma_shift);
  const std::size_t first = std::max(opt.warmup, opt.window - 1);
  HorizonResult r;
  r.wn = wn;
  r.rms.assign(opt.max_horizon + 1, 0.0);
  for (std::size_t k = first; k < x.size(); ++k) {
    if (std::isnan(o[k])) {
      continue;
    }
    ++r.scored;
    const double* win = f.data() + (k + 1 - opt.window);
    for (std::size_t p = 0; p <= opt.max_horizon; ++p) {
      const auto fit = blocks::GreyPredictorGM11::predict(
          win, opt.window, static_cast<std::int64_t>(p), opt.paper_exp);
      const double pred = fit.valid ? std::clamp(fit.prediction, opt.out_min, opt.out_max) : f[k];
      const double e = pred - o[k];
      r.rms[p] += e * e;
    }
  }
  if (r.scored == 0) {
    throw std::invalid_argument("choose_horizon: the record is too short to score");
  }
  r.best_rms = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p <= opt.max_horizon; ++p) {
    r.rms[p] = std::sqrt(r.rms[p] / static_cast<double>(r.scored));
    if (r.rms[p] < r.best_rms) {
      r.best_rms = r.rms[p];
      r.best_p = p;
    }
  }
  return r;
}

HorizonResult pool_horizons(const std::vector<HorizonResult>& results) {
  if (results.empty()) {
    throw std::invalid_argument("pool_horizons: no results");
  }
  HorizonResult r;
  r.wn = results.front().wn;
  r.rms.assign(results.front().rms.size(), 0.0);
  for (const HorizonResult& x : results) {
    if (x.rms.size() != r.rms.size()) {
      throw std::invalid_argument("pool_horizons: results of different horizon ranges");
    }
    for (std::size_t p = 0; p < r.rms.size(); ++p) {
      r.rms[p] += x.rms[p] * x.rms[p] * static_cast<double>(x.scored);
    }
    r.scored += x.scored;
  }
  if (r.scored == 0) {
    throw std::invalid_argument("pool_horizons: nothing scored");
  }
  r.best_rms = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < r.rms.size(); ++p) {
    r.rms[p] = std::sqrt(r.rms[p] / static_cast<double>(r.scored));
    if (r.rms[p] < r.best_rms) {
      r.best_rms = r.rms[p];
      r.best_p = p;
    }
  }
  return r;
}

}  // namespace edm::greyhorizon
