#include "edm/blocks/self_tuning_regulator.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {

std::vector<rt::ParamError> SelfTuningRegulatorParams::validate() const {
  std::vector<rt::ParamError> errs;
  if (beta00 == 0.0) {
    errs.push_back({"beta00", "must be != 0 (the law divides by it)"});
  }
  rt::require_ordered(errs, "u_v_min", u_v_min, "u_v_max", u_v_max);
  rt::require_ordered(errs, "to_min_us", to_min_us, "to_max_us", to_max_us);
  rt::require_ordered(errs, "p0", 2.0 * p0, "trace_max", trace_max);
  if (errs.empty()) {
    rt::require_range(errs, "u_v_initial", u_v_initial, u_v_min, u_v_max);
    rt::require_range(errs, "to_initial_us", to_initial_us, to_min_us, to_max_us);
    rt::require_ordered(errs, "y_rv_min", y_rv_min, "y_rv_good", y_rv_good);
    rt::require_ordered(errs, "y_rt_min", y_rt_min, "y_rt_good", y_rt_good);
  }
  return errs;
}

void SelfTuningRegulator::activate() noexcept {
  const auto& p = params_;
  const double main_init[2] = {p.beta01_init, p.beta0c_init};
  main_.reset(2, p.p0, main_init);
  const double aux_init[1] = {p.beta1c_init};
  aux_.reset(1, p.p0, aux_init);
  hist_v_.fill(std::clamp(p.u_v_initial, p.u_v_min, p.u_v_max));
  u_t_ = std::clamp(p.to_initial_us, p.to_min_us, p.to_max_us);
  aux_turn_ = false;
  sat_v_ = false;
  sat_t_ = false;
  y_rv_ = p.y_rv_good;
  y_rt_ = p.y_rt_good;
  y_v_out_.set(0.0);
  y_t_out_.set(0.0);
  k1_.set(p.ti_us / (p.ti_us + u_t_));
  saturated_.set(false);
  publish();
}

void SelfTuningRegulator::publish() noexcept {
  // §3: the automatic gain K1 = ti/tp of the off time output now, on the Us input.
  const double k1_us = params_.k1_on_us ? params_.ti_us / (params_.ti_us + u_t_) : 1.0;
  servo_ref_v_.set(k1_us * params_.us_per_unit_v * hist_v_[0]);
  off_time_us_.set(u_t_);
  u_v_out_.set(hist_v_[0]);
  y_rv_out_.set(y_rv_);
  y_rt_out_.set(y_rt_);
  beta01_.set(main_.theta(0));
  beta0c_.set(main_.theta(1));
  beta1c_.set(aux_.theta(0));
}

rt::BlockStatus SelfTuningRegulator::update(const rt::CycleContext& /*ctx*/) noexcept {
  const auto& p = params_;
  const double phi_e = ratio_normal_.get();
  const double phi_e2 = ratio_transient_arc_.get();
  const double phi_a = ratio_stable_arc_.get();
  const double phi_s = ratio_short_.get();
  const double rv_in = y_rv_ref_.get();
  const double rt_in = y_rt_ref_.get();
  if (!std::isfinite(phi_e) || !std::isfinite(phi_e2) || !std::isfinite(phi_a) ||
      !std::isfinite(phi_s) || !std::isfinite(rv_in) || !std::isfinite(rt_in)) {
    return fault("a non-finite state ratio or reference", phi_a);
  }
  // K1 = ti/tp of the period just measured (the off time commanded last sample).
  const double k1 = p.ti_us / (p.ti_us + u_t_);
  const double y_v = phi_e + 2.0 * phi_e2 + 2.0 * phi_a + 2.0 * phi_s;
  const double y_t = k1 * (phi_e + 2.0 * phi_e2 + 2.0 * phi_a);
  y_v_out_.set(y_v);
  y_t_out_.set(y_t);
  k1_.set(k1);
  // §4: the loops in turn (alternate) or both every sample.
  const bool do_main = !p.alternate || !aux_turn_;
  const bool do_aux = !p.alternate || aux_turn_;
  if (p.alternate) {
    aux_turn_ = !aux_turn_;
  }
  if (!enable_.get()) {
    // Hold u; the history still shifts, so the model's timing stays true on re-enable.
    if (do_main) {
      for (std::size_t i = hist_v_.size() - 1; i > 0; --i) {
        hist_v_[i] = hist_v_[i - 1];
      }
    }
    sat_v_ = false;
    sat_t_ = false;
    saturated_.set(false);
    publish();
    return rt::BlockStatus::kOk;
  }

  // Reference decision (§3): each loop's on its own samples (in turn, every other sample).
  if (phi_a > p.stable_arc_limit) {
    if (do_main) {
      y_rv_ = std::max(p.y_rv_min, y_rv_ - p.ref_step);
    }
    if (do_aux) {
      y_rt_ = std::max(p.y_rt_min, y_rt_ - p.ref_step);
    }
  } else if (phi_e2 < p.transient_arc_limit) {
    if (do_main) {
      y_rv_ += p.ref_rise * (p.y_rv_good - y_rv_);
    }
    if (do_aux) {
      y_rt_ += p.ref_rise * (p.y_rt_good - y_rt_);
    }
  }
  const double y_rv = rv_in > 0.0 ? rv_in : y_rv_;
  const double y_rt = rt_in > 0.0 ? rt_in : y_rt_;

  // Main loop: y_v(k) − β00·u_v(k−d−1) = β01·u_v(k−d−2) + β0c (k counts main-loop samples).
  if (do_main) {
    const auto d = static_cast<std::size_t>(p.delay_v);
    const double phi_v[2] = {hist_v_[d + 1], 1.0};
    const RlsCore::Result rv =
        main_.update(phi_v, y_v - p.beta00 * hist_v_[d], p.lambda, p.trace_max);
    if (!rv.ok) {
      return fault("the main loop's RLS update diverged");
    }
    // Minimum-variance law: the model's prediction put on the reference.
    const double u_v_raw = (y_rv - main_.theta(0) * hist_v_[0] - main_.theta(1)) / p.beta00;
    if (!std::isfinite(u_v_raw)) {
      return fault("the main loop's command is not finite", u_v_raw);
    }
    const double u_v = std::clamp(u_v_raw, p.u_v_min, p.u_v_max);
    for (std::size_t i = hist_v_.size() - 1; i > 0; --i) {
      hist_v_[i] = hist_v_[i - 1];
    }
    hist_v_[0] = u_v;
    sat_v_ = u_v != u_v_raw;
  }
  // Auxiliary loop: y_t(k) − β10·u_t(k−1) = β1c.
  if (do_aux) {
    const double beta10 = -1.0 / p.ti_us;
    const double one[1] = {1.0};
    const RlsCore::Result rt_res = aux_.update(one, y_t - beta10 * u_t_, p.lambda, p.trace_max);
    if (!rt_res.ok) {
      return fault("the auxiliary loop's RLS update diverged");
    }
    const double u_t_raw = (y_rt - aux_.theta(0)) / beta10;
    if (!std::isfinite(u_t_raw)) {
      return fault("the auxiliary loop's command is not finite", u_t_raw);
    }
    u_t_ = std::clamp(u_t_raw, p.to_min_us, p.to_max_us);
    sat_t_ = u_t_ != u_t_raw;
  }
  // A loop held this sample (alternate) keeps its clamped value and its flag.
  const bool saturated = sat_v_ || sat_t_;
  saturated_.set(saturated);
  publish();
  return saturated ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
