#include "edm/programs/job_figures.hpp"

#include <algorithm>
#include <chrono>

namespace edm::programs {

void JobFigures::begin(rt::TimePoint start) noexcept {
  start_ = start;
  wear_before_block_ = 0.0;
  depth_before_block_ = 0.0;
  drilled_before_block_ = 0.0;
  job_time_s.set(0.0);
  job_pulses.set(0);
  job_shorts.set(0);
  job_arcs.set(0);
  job_depth_mm.set(0.0);
  job_wear_mm.set(0.0);
  job_holes.set(0);
  job_drilled_mm.set(0.0);
}

void JobFigures::count(rt::TimePoint now, const Counts& c) noexcept {
  job_time_s.set(std::chrono::duration<double>(now - start_).count());
  const std::int64_t arcs = c.n_transient_arc + c.n_stable_arc;
  job_pulses.set(job_pulses.get() + c.n_open + c.n_normal + arcs + c.n_short);
  job_shorts.set(job_shorts.get() + c.n_short);
  job_arcs.set(job_arcs.get() + arcs);
}

void JobFigures::note_drill(double depth_mm, double wear_mm) noexcept {
  job_depth_mm.set(std::max(job_depth_mm.get(), depth_mm));
  job_wear_mm.set(wear_before_block_ + wear_mm);
  job_drilled_mm.set(drilled_before_block_ + depth_mm);
}

}  // namespace edm::programs
