#include "edm/blocks/orbit_expander.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {

std::vector<rt::ParamError> OrbitExpanderParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_finite(errs, "kr", kr);
  rt::require_finite(errs, "dr_max_mm", dr_max_mm);
  if (std::isfinite(kr)) {
    rt::require_non_negative(errs, "kr", kr);
  }
  if (std::isfinite(dr_max_mm)) {
    rt::require_non_negative(errs, "dr_max_mm", dr_max_mm);
  }
  rt::require_range(errs, "samples_per_rev", static_cast<double>(samples_per_rev), 0.0,
                    static_cast<double>(OrbitExpander::kMaxSamplesPerRev));
  return errs;
}

void OrbitExpander::visit_pins(rt::PinVisitor& v) {
  v.input("start", start_);
  v.input("r0_mm", r0_, "mm");
  v.input("final_radius_mm", final_radius_, "mm");
  v.input("enable", enable_);
  v.input("td_us", td_, "us");
  v.input("valid", valid_);
  v.input("rev_pulse", rev_pulse_);
  v.output("radius_mm", radius_, "mm");
  v.output("dr_mm", dr_, "mm");
  v.output("tdm_us", tdm_, "us");
  v.output("revolutions", revolutions_);
  v.output("busy", busy_);
  v.output("done", done_);
}

void OrbitExpander::activate() noexcept {
  radius_mm_ = 0.0;
  final_mm_ = 0.0;
  dr_mm_ = 0.0;
  tdm_us_ = 0.0;
  sum_us_ = 0.0;
  n_valid_ = 0;
  n_samples_ = 0;
  revs_ = 0;
  busy_state_ = false;
  done_state_ = false;
  prev_start_ = false;
  prev_rev_ = false;
  publish();
}

rt::BlockStatus OrbitExpander::update(const rt::CycleContext& /*ctx*/) noexcept {
  const bool start = start_.get();
  const bool start_edge = start && !prev_start_;
  prev_start_ = start;
  // rev_pulse edges are tracked in every cycle so that a pulse held high across a pause or a
  // start does not count twice.
  const bool rev = rev_pulse_.get();
  const bool rev_edge = rev && !prev_rev_;
  prev_rev_ = rev;

  if (start_edge && !busy_state_) {
    const double r0 = r0_.get();
    const double fin = final_radius_.get();
    if (!std::isfinite(r0) || !std::isfinite(fin) || r0 < 0.0 || fin < r0) {
      publish();
      return rt::BlockStatus::kFault;
    }
    radius_mm_ = r0;
    final_mm_ = fin;
    dr_mm_ = 0.0;
    tdm_us_ = 0.0;
    sum_us_ = 0.0;
    n_valid_ = 0;
    n_samples_ = 0;
    revs_ = 0;
    busy_state_ = r0 < fin;
    done_state_ = !busy_state_;
    publish();
    return rt::BlockStatus::kOk;  // collecting starts with the next sample
  }
  if (!busy_state_ || !enable_.get()) {
    publish();
    return rt::BlockStatus::kOk;
  }

  rt::BlockStatus status = rt::BlockStatus::kOk;
  if (valid_.get()) {
    const double td = td_.get();
    if (std::isfinite(td)) {
      sum_us_ += td;
      ++n_valid_;
    } else {
      status = rt::BlockStatus::kFault;
    }
  }
  ++n_samples_;
  const bool rev_end =
      params_.samples_per_rev > 0 ? n_samples_ >= params_.samples_per_rev : rev_edge;
  if (!rev_end) {
    publish();
    return status;
  }

  double dr = 0.0;
  tdm_us_ = 0.0;
  if (n_valid_ > 0) {
    const double tdm = sum_us_ / static_cast<double>(n_valid_);
    if (std::isfinite(tdm)) {
      tdm_us_ = tdm;
      const double want = params_.kr * tdm;
      dr = std::clamp(want, 0.0, params_.dr_max_mm);
      if (want > params_.dr_max_mm && status == rt::BlockStatus::kOk) {
        status = rt::BlockStatus::kSaturated;
      }
    } else {
      status = rt::BlockStatus::kFault;
    }
  }
  if (dr >= final_mm_ - radius_mm_) {
    dr = final_mm_ - radius_mm_;
    radius_mm_ = final_mm_;
    busy_state_ = false;
    done_state_ = true;
  } else {
    radius_mm_ += dr;
  }
  dr_mm_ = dr;
  ++revs_;
  sum_us_ = 0.0;
  n_valid_ = 0;
  n_samples_ = 0;
  publish();
  return status;
}

void OrbitExpander::publish() noexcept {
  radius_.set(radius_mm_);
  dr_.set(dr_mm_);
  tdm_.set(tdm_us_);
  revolutions_.set(revs_);
  busy_.set(busy_state_);
  done_.set(done_state_);
}

}  // namespace edm::blocks
