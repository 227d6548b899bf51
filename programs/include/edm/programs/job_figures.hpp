#pragma once
// JobFigures: the figures of one job for the HMI's job report, kept as outputs of the job
// sequencer so they survive the HMI (reset when a job begins, frozen when it ends):
//   job_time_s   machine time in the job
//   job_pulses   Σ n_open + n_normal + n_transient_arc + n_stable_arc + n_short over the cycles
//   job_shorts   Σ n_short;   job_arcs  Σ n_transient_arc + n_stable_arc
//   job_depth_mm deepest depth_reached_mm of the job's drilling blocks
//   job_wear_mm  estimated electrode wear (seed 004 eq. 8), summed over the drilling blocks
//   job_holes    drilling blocks begun;   job_drilled_mm Σ depth reached over them (the depth
//                an electrode's measured wear ratio is taken over)
// The outputs are listed in the owner's pin table. RT-safety: every member but the constructor
// is RT-safe. Not thread-safe: the owning task calls them.

#include <cstdint>

#include "edm/runtime/pin.hpp"
#include "edm/runtime/time.hpp"

namespace edm::programs {

class JobFigures {
 public:
  /// The I/O pulse counts of one cycle (unwired count inputs read 0).
  struct Counts {
    std::int64_t n_open{0};
    std::int64_t n_normal{0};
    std::int64_t n_transient_arc{0};
    std::int64_t n_stable_arc{0};
    std::int64_t n_short{0};
  };

  explicit JobFigures(rt::PinTable& owner)
      : job_time_s{owner, "job_time_s", "s"},
        job_pulses{owner, "job_pulses"},
        job_shorts{owner, "job_shorts"},
        job_arcs{owner, "job_arcs"},
        job_depth_mm{owner, "job_depth_mm", "mm"},
        job_wear_mm{owner, "job_wear_mm", "mm"},
        job_holes{owner, "job_holes"},
        job_drilled_mm{owner, "job_drilled_mm", "mm"} {}

  rt::Output<double> job_time_s;
  rt::Output<std::int64_t> job_pulses;
  rt::Output<std::int64_t> job_shorts;
  rt::Output<std::int64_t> job_arcs;
  rt::Output<double> job_depth_mm;
  rt::Output<double> job_wear_mm;
  rt::Output<std::int64_t> job_holes;
  rt::Output<double> job_drilled_mm;

  /// A job begins at `start`: every figure is 0.
  void begin(rt::TimePoint start) noexcept;
  /// One cycle of the job at `now`.
  void count(rt::TimePoint now, const Counts& c) noexcept;
  /// A drilling block begins: its wear adds to the job's wear so far.
  void begin_drill_block() noexcept {
    wear_before_block_ = job_wear_mm.get();
    depth_before_block_ = job_depth_mm.get();
    drilled_before_block_ = job_drilled_mm.get();
    job_holes.set(job_holes.get() + 1);
  }
  /// The running drilling block's depth reached and estimated wear.
  void note_drill(double depth_mm, double wear_mm) noexcept;
  /// The running drilling block's depth measured by touch: it replaces the block's estimate.
  void note_measured(double depth_mm) noexcept {
    job_depth_mm.set(depth_before_block_ > depth_mm ? depth_before_block_ : depth_mm);
    job_drilled_mm.set(drilled_before_block_ + depth_mm);
  }

 private:
  rt::TimePoint start_{};
  double wear_before_block_{0.0};     // job_wear_mm when the current drilling block began
  double depth_before_block_{0.0};    // job_depth_mm when the current drilling block began
  double drilled_before_block_{0.0};  // job_drilled_mm when the current drilling block began
};

}  // namespace edm::programs
