#include "edm/blocks/self_tuning_fuzzy_pi.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {
namespace {

constexpr int kTerms = 3;  // term indices −3…+3 (NB…PB)

// Triangle of half-width 1 at `peak`.
double mu(double x, int peak) noexcept {
  return std::max(0.0, 1.0 - std::fabs(x - static_cast<double>(peak)));
}

}  // namespace

std::vector<rt::ParamError> SelfTuningFuzzyPIParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_ordered(errs, "u_min_us", u_min_us, "u_max_us", u_max_us);
  rt::require_ordered(errs, "v_min_v", v_min_v, "v_max_v", v_max_v);
  if (errs.empty()) {
    rt::require_range(errs, "u_initial_us", u_initial_us, u_min_us, u_max_us);
    rt::require_range(errs, "v_initial_v", v_initial_v, v_min_v, v_max_v);
  }
  return errs;
}

double SelfTuningFuzzyPI::rule_output(double e_scaled, double ce_scaled) noexcept {
  const double e = std::clamp(e_scaled, -static_cast<double>(kTerms), static_cast<double>(kTerms));
  const double ce =
      std::clamp(ce_scaled, -static_cast<double>(kTerms), static_cast<double>(kTerms));
  double num = 0.0;
  double den = 0.0;
  for (int i = -kTerms; i <= kTerms; ++i) {
    const double mi = mu(e, i);
    if (mi <= 0.0) {
      continue;
    }
    for (int j = -kTerms; j <= kTerms; ++j) {
      const double w = std::min(mi, mu(ce, j));
      if (w <= 0.0) {
        continue;
      }
      const int out = std::clamp(-(i + j), -kTerms, kTerms);  // Table 3
      num += w * static_cast<double>(out);  // height method: the output term's peak
      den += w;
    }
  }
  return den > 0.0 ? num / den : 0.0;  // den > 0 always: the terms cover [−3, 3]
}

void SelfTuningFuzzyPI::activate() noexcept {
  const auto& p = params_;
  u_ = std::min(std::max(p.u_initial_us, p.u_min_us), p.u_max_us);
  v_ = std::min(std::max(p.v_initial_v, p.v_min_v), p.v_max_v);
  have_prev_ = false;
  prev_p_ = 0.0;
  samples_ = 0;
  arc_off_time_us_.set(u_);
  servo_ref_v_.set(v_);
  du_.set(0.0);
  phi_.set(1.0);
  psi_.set(1.0);
  error_.set(0.0);
  saturated_.set(false);
}

rt::BlockStatus SelfTuningFuzzyPI::update(const rt::CycleContext& /*ctx*/) noexcept {
  const auto& p = params_;
  const double rab_p_in = rab_p_.get();
  const double rab_f_in = rab_f_.get();
  const double ref_in = rab_ref_.get();
  if (!std::isfinite(rab_p_in) || !std::isfinite(rab_f_in) || !std::isfinite(ref_in)) {
    return fault("a non-finite Rab, filtered Rab or reference", rab_p_in);
  }
  const double rab_p = std::clamp(rab_p_in, 0.0, 1.0);  // a ratio; predictions may overshoot
  const double rab_f = std::clamp(rab_f_in, 0.0, 1.0);
  const double ce = have_prev_ ? prev_p_ - rab_p : 0.0;
  prev_p_ = rab_p;
  have_prev_ = true;
  const bool settling = samples_ < p.settle_samples;
  if (settling) {
    ++samples_;
  }
  if (settling || !enable_.get()) {
    // Idle: follow the commands another controller applies (when wired, > 0), so that the
    // incremental law of eq. 4-5 continues from them when this block takes over (bumpless).
    const double tu = track_u_.get();
    const double tv = track_v_.get();
    if (std::isfinite(tu) && tu > 0.0) {
      u_ = std::min(std::max(tu, p.u_min_us), p.u_max_us);
    }
    if (std::isfinite(tv) && tv > 0.0) {
      v_ = std::min(std::max(tv, p.v_min_v), p.v_max_v);
    }
    arc_off_time_us_.set(u_);
    servo_ref_v_.set(v_);
    du_.set(0.0);
    saturated_.set(false);
    return rt::BlockStatus::kOk;
  }
  const double ref = ref_in > 0.0 ? ref_in : p.rab_ref_default;
  const double e = ref - rab_p;
  const double big_e = p.ge * e;
  const double big_ce = p.gce * ce;
  const double du = rule_output(big_e, big_ce);
  // f(x, a) = (1 − e^(−a·x))/(1 + e^(−a·x)) = tanh(a·x/2), with x = CE and a = 5·E.
  const double f = std::tanh(5.0 * big_e * big_ce / 2.0);
  const double phi = 0.5 * (1.0 + p.alpha) + 0.5 * (1.0 - p.alpha) * f;
  double psi = 1.0;
  if (e < p.overload_error) {
    psi = std::max(p.psi_min, p.ol * (1.0 + p.dpf_gain * (rab_p - rab_f)));
  }
  const double scale = std::fabs(e) * phi * psi;
  const double u_next = u_ + du * p.ku * scale;
  const double v_next = v_ + du * p.kv * scale;
  if (!std::isfinite(u_next) || !std::isfinite(v_next)) {
    return fault("the outputs u, v overflowed",
                 u_next);  // finite inputs, but the product overflowed
  }
  u_ = std::min(std::max(u_next, p.u_min_us), p.u_max_us);
  v_ = std::min(std::max(v_next, p.v_min_v), p.v_max_v);
  const bool saturated = u_ != u_next || v_ != v_next;
  arc_off_time_us_.set(u_);
  servo_ref_v_.set(v_);
  du_.set(du);
  phi_.set(phi);
  psi_.set(psi);
  error_.set(e);
  saturated_.set(saturated);
  return saturated ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
