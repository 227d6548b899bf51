#include "edm/blocks/grey_predictor_gm11.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {
std::vector<rt::ParamError> GreyPredictorGM11Params::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_ordered(errs, "out_min", out_min, "out_max", out_max);
  return errs;
}

GreyPredictorGM11::Fit GreyPredictorGM11::predict(const double* x, std::size_t n,
                                                  std::int64_t horizon, bool paper_exp) noexcept {
  Fit f;
  if (n < 2) {
    return f;
  }
  // Means of z(k) and x⁰(k) over k = 2…n.
  const auto m = static_cast<double>(n - 1);
  double x1 = x[0];  // x¹(k−1)
  double zsum = 0.0;
  double xsum = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    zsum += x1 + 0.5 * x[k];
    xsum += x[k];
    x1 += x[k];
  }
  const double zbar = zsum / m;
  const double xbar = xsum / m;
  double szz = 0.0;
  double szx = 0.0;
  x1 = x[0];
  for (std::size_t k = 1; k < n; ++k) {
    const double dz = x1 + 0.5 * x[k] - zbar;
    szz += dz * dz;
    szx += dz * (x[k] - xbar);
    x1 += x[k];
  }
  if (!(szz > 0.0)) {
    return f;  // all z equal: no slope to fit
  }
  const double c = -szx / szz;
  const double b = xbar + c * zbar;
  if (!std::isfinite(c) || !std::isfinite(b)) {
    return f;  // huge inputs overflowed the sums
  }
  f.c = c;
  f.b = b;
  if (!(std::fabs(c) < 2.0)) {
    return f;
  }
  const double k_ahead = static_cast<double>(n) + static_cast<double>(horizon);  // index n + p
  double y = 0.0;
  if (paper_exp) {
    const double e = c == 0.0 ? 1.0 : std::expm1(c) / c;
    y = (b - c * x[0]) * e * std::exp(-c * (k_ahead - 1.0));
  } else {
    const double rho = (1.0 - 0.5 * c) / (1.0 + 0.5 * c);
    y = (b - c * x[0]) / (1.0 + 0.5 * c) * std::pow(rho, k_ahead - 2.0);
  }
  if (!std::isfinite(y)) {
    return f;
  }
  f.prediction = y;
  f.valid = true;
  return f;
}

std::vector<rt::ParamError> GreyPredictorGM11::configure(const rt::BlockSetup& /*setup*/) {
  return configure_checked(params_, [this] {
    window_.allocate(static_cast<std::size_t>(params_.window));
    work_.assign(window_.capacity(), 0.0);
    activate();
  });
}

void GreyPredictorGM11::activate() noexcept {
  window_.clear();
  out_.set(0.0);
  c_.set(0.0);
  b_.set(0.0);
  valid_.set(false);
}

rt::BlockStatus GreyPredictorGM11::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double x = in_.get();
  const std::size_t n = window_.capacity();
  if (!std::isfinite(x) || n == 0) {
    return fault("a non-finite input, or not configured", x);
  }
  window_.push(x);
  const auto clamped = [this](double y) noexcept {
    return std::min(std::max(y, params_.out_min), params_.out_max);
  };
  if (!window_.full()) {
    out_.set(clamped(x));
    valid_.set(false);
    return rt::BlockStatus::kOk;
  }
  for (std::size_t i = 0; i < n; ++i) {
    work_[i] = window_[i];  // oldest first
  }
  const Fit f = predict(work_.data(), n, params_.horizon, params_.paper_exp);
  c_.set(f.c);
  b_.set(f.b);
  out_.set(clamped(f.valid ? f.prediction : x));
  valid_.set(f.valid);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
