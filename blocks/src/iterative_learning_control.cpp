#include "edm/blocks/iterative_learning_control.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {
std::vector<rt::ParamError> IterativeLearningControlParams::validate() const {
  std::vector<rt::ParamError> errs;
  if (p0 == 0.0) {
    errs.push_back({"p0", "must be != 0 (l1 divides by it)"});
  }
  if (k_delta == 0.0) {
    errs.push_back({"k_delta", "must be != 0 (the gains divide by it)"});
  }
  rt::require_ordered(errs, "u_min", u_min, "u_max", u_max);
  if (errs.empty()) {
    rt::require_range(errs, "u_initial", u_initial, u_min, u_max);
  }
  return errs;
}

IterativeLearningControl::Gains IterativeLearningControl::gains(
    const IterativeLearningControlParams& p) noexcept {
  const double q0 = 1.0 - p.q_pole;
  Gains g;
  g.l1 = (q0 - p.lambda3) / (p.k_delta * q0 * p.p0);
  g.l2 = (2.0 - p.lambda1 - p.lambda2) / p.k_delta;
  g.l3 = (1.0 - p.lambda1) * (1.0 - p.lambda2) / p.k_delta;
  return g;
}

std::vector<rt::ParamError> IterativeLearningControl::configure(const rt::BlockSetup& /*setup*/) {
  return configure_checked(params_, [this] {
    u_.assign(static_cast<std::size_t>(params_.n_samples), params_.u_initial);
    e_.assign(u_.size(), 0.0);
  });
}

void IterativeLearningControl::activate() noexcept {
  std::fill(u_.begin(), u_.end(), params_.u_initial);
  std::fill(e_.begin(), e_.end(), 0.0);
  idx_ = -1;
  cycle_start_edge_.reset();
  overrun_ = false;
  x_ = 0.0;
  last_e_ = 0.0;
  cycles_done_ = 0;
  warm_done_ = 0;
  prev_warm_mean_ = 0.0;
  warm_ = params_.warm_cycles > 0;
  active_.set(!warm_);
  const Gains g = gains(params_);
  l1_.set(g.l1);
  l2_.set(g.l2);
  l3_.set(g.l3);
  u_out_.set(params_.u_initial);
  mean_error_.set(0.0);
  x_out_.set(0.0);
  sample_.set(-1);
  cycles_.set(0);
}

void IterativeLearningControl::learn() noexcept {
  const auto& p = params_;
  const Gains g = gains(p);
  const std::size_t n = u_.size();
  double mean = 0.0;
  for (double e : e_) {
    mean += e;
  }
  mean /= static_cast<double>(n);
  // v = u_j + L·e_j (into u_, in place), then u_j+1 = Q·v.
  for (std::size_t i = 0; i < n; ++i) {
    u_[i] += g.l1 * (e_[i] - mean) + g.l2 * mean + g.l3 * x_;
  }
  x_ += mean;
  const double a = p.q_pole;
  if (a > 0.0) {
    const double v0 = u_[0];
    double s = 0.0;
    for (std::size_t i = 1; i < n; ++i) {
      s = a * s + (1.0 - a) * (u_[i] - v0);
      u_[i] = v0 + s;
    }
  }
  for (double& u : u_) {
    u = std::min(std::max(u, p.u_min), p.u_max);
  }
  ++cycles_done_;
  mean_error_.set(mean);
  x_out_.set(x_);
  cycles_.set(cycles_done_);
}

void IterativeLearningControl::end_warm_cycle() noexcept {
  double mean = 0.0;
  for (double u : u_) {
    mean += u;
  }
  mean /= static_cast<double>(u_.size());
  ++warm_done_;
  if (warm_done_ >= params_.warm_cycles) {
    const Gains g = gains(params_);
    // The other controller's advance per cycle becomes this one's (l3·x at zero mean error).
    x_ = warm_done_ >= 2 && g.l3 != 0.0 ? (mean - prev_warm_mean_) / g.l3 : 0.0;
    learn();
    warm_ = false;
    active_.set(true);
  }
  prev_warm_mean_ = mean;
}

rt::BlockStatus IterativeLearningControl::update(const rt::CycleContext& /*ctx*/) noexcept {
  const auto& p = params_;
  const double y = y_.get();
  const double ref = y_ref_.get();
  const bool rising = cycle_start_edge_(cycle_start_.get());
  const auto n = static_cast<std::int64_t>(u_.size());
  if (!std::isfinite(y) || !std::isfinite(ref) || n == 0) {
    return fault("a non-finite measurement or reference, or no learning samples", y);
  }
  const double track = track_.get();
  if (warm_ && (!track_.connected() || !std::isfinite(track))) {
    return fault("warm_cycles > 0 needs the applied position (track) wired and finite",
                 track);  // warm_cycles > 0 needs the applied position wired
  }
  const bool learning = enable_.get();
  if (idx_ >= 0) {
    last_e_ = p.e_max > 0.0 ? std::clamp(ref - y, -p.e_max, p.e_max) : ref - y;
    e_[static_cast<std::size_t>(idx_)] = last_e_;
  }
  const bool boundary = rising || (p.auto_cycle && (idx_ < 0 || idx_ == n - 1));
  if (boundary) {
    if (idx_ >= 0) {
      const auto last = static_cast<std::size_t>(idx_);
      for (std::int64_t i = idx_ + 1; i < n; ++i) {
        e_[static_cast<std::size_t>(i)] = last_e_;  // a cycle cut short
        if (warm_) {
          u_[static_cast<std::size_t>(i)] = u_[last];
        }
      }
      if (warm_) {
        end_warm_cycle();
      } else if (learning) {
        learn();
      }
    }
    idx_ = 0;
    overrun_ = false;
  } else if (idx_ >= 0) {
    if (idx_ + 1 < n) {
      ++idx_;
    } else {
      overrun_ = true;
    }
  }
  if (warm_) {
    if (idx_ >= 0) {
      u_[static_cast<std::size_t>(idx_)] = track;  // u_j(k): the position applied at sample k
      sample_.set(idx_);
    }
    u_out_.set(track);
    return rt::BlockStatus::kOk;
  }
  if (idx_ < 0) {
    u_out_.set(p.u_initial);
    return rt::BlockStatus::kOk;
  }
  u_out_.set(u_[static_cast<std::size_t>(idx_)]);
  sample_.set(idx_);
  return overrun_ ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
