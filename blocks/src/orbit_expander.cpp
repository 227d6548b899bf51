#include "edm/blocks/orbit_expander.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {

void OrbitExpander::activate() noexcept {
  radius_mm_ = 0.0;
  final_mm_ = 0.0;
  clear_progress();
  busy_state_ = false;
  done_state_ = false;
  start_edge_.reset();
  rev_edge_.reset();
  publish();
}

rt::BlockStatus OrbitExpander::update(const rt::CycleContext& /*ctx*/) noexcept {
  const bool start_edge = start_edge_(start.get());
  // rev_pulse edges are tracked in every cycle so that a pulse held high across a pause or a
  // start does not count twice.
  const bool rev_edge = rev_edge_(rev_pulse.get());

  if (start_edge && !busy_state_) {
    const double r0 = r0_mm.get();
    const double fin = final_radius_mm.get();
    if (!std::isfinite(r0) || !std::isfinite(fin) || r0 < 0.0 || fin < r0) {
      publish();
      return fault("a non-finite or negative start radius, or a final radius below it", r0);
    }
    radius_mm_ = r0;
    final_mm_ = fin;
    clear_progress();
    busy_state_ = r0 < fin;
    done_state_ = !busy_state_;
    publish();
    return rt::BlockStatus::kOk;  // collecting starts with the next sample
  }
  if (!busy_state_ || !enable.get()) {
    publish();
    return rt::BlockStatus::kOk;
  }

  rt::BlockStatus status = rt::BlockStatus::kOk;
  if (valid.get()) {
    const double td = td_us.get();
    if (std::isfinite(td)) {
      sum_us_ += td;
      ++n_valid_;
    } else {
      status = fault("a non-finite Td while orbiting", td);
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
      status = fault("a non-finite mean Td over the revolution", tdm);
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

void OrbitExpander::clear_progress() noexcept {
  dr_mm_ = 0.0;
  tdm_us_ = 0.0;
  sum_us_ = 0.0;
  n_valid_ = 0;
  n_samples_ = 0;
  revs_ = 0;
}

void OrbitExpander::publish() noexcept {
  radius_mm.set(radius_mm_);
  dr_mm.set(dr_mm_);
  tdm_us.set(tdm_us_);
  revolutions.set(revs_);
  busy.set(busy_state_);
  done.set(done_state_);
}

}  // namespace edm::blocks
