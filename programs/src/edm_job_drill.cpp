// EdmJob's drilling blocks: the drill child's cycle and, with the depth probe (DepthProbe,
// docs/blocks.md "The depth probe"), its moves on this job.
#include <algorithm>
#include <cmath>

#include "edm/programs/edm_job.hpp"

namespace edm::programs {
namespace {
using machining::MotionBlock;
using machining::MotionKind;

constexpr auto kDone = static_cast<std::int64_t>(DeepHoleDrill::State::kDone);
constexpr auto kDrilling = static_cast<std::int64_t>(DeepHoleDrill::State::kDrill);

}  // namespace

// The probe's rapids, touches and drillings on this job's interpolator, loops, manual touch
// and drill, for one cycle.
class EdmJob::ProbeMovesOfJob final : public ProbeMoves {
 public:
  ProbeMovesOfJob(EdmJob& job, const rt::CycleContext& ctx, bool hold,
                  rt::BlockStatus& status) noexcept
      : job_(job), ctx_(ctx), hold_(hold), status_(status) {}

  bool rapid(double x, double y, double z, bool begin) noexcept override {
    if (begin) {
      job_.probe_move_ = MotionBlock{};
      job_.probe_move_.kind = MotionKind::kRapid;
      job_.probe_move_.line = job_.drill_return_.line;
      job_.probe_move_.col = job_.drill_return_.col;
      job_.probe_move_.target = {x, y, z};
      job_.step_ = Step::kEnter;
    }
    if (!job_.run_linear(job_.probe_move_, ctx_, hold_, status_)) return false;
    job_.step_ = Step::kBusy;
    return true;
  }

  bool touch(bool begin, bool& ok, double& z) noexcept override {
    // The touch drives the axes; the loops follow where they are (no error builds up in them).
    job_.hold_x_ = job_.pos.x().get();
    job_.hold_y_ = job_.pos.y().get();
    job_.hold_z_ = job_.pos.z().get();
    job_.hold_position();
    if (begin) {
      if (!job_.manual_.begin_job_touch_z(ctx_)) {
        ok = false;
        return true;
      }
      return false;
    }
    if (job_.manual_.job_touch_busy()) return false;
    ok = job_.manual_.job_touch_ok();
    z = job_.manual_.job_touch_z_mm();
    return true;
  }

  void drill(double depth_mm, const DrillFrom& from) noexcept override {
    job_.hold_position();
    job_.start_drill(depth_mm, from);
  }

 private:
  EdmJob& job_;
  const rt::CycleContext& ctx_;
  bool hold_;
  rt::BlockStatus& status_;
};

void EdmJob::start_drill(double depth_mm, const DrillFrom& from) noexcept {
  drill_.depth_done_mm.drive(from.depth_done_mm);
  drill_.resume_touch_z_mm.drive(from.resume_touch_z_mm);
  drill_.resume_wear_mm.drive(from.resume_wear_mm);
  drill_.contact_z_mm.drive(from.contact_z_mm);
  drill_.contact_depth_mm.drive(from.contact_depth_mm);
  drill_.depth_mm.drive(depth_mm);
  drill_.start.drive(true);
  probe_.drilling_at(pos.z().get(), true);
}

bool EdmJob::run_drill(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                       rt::BlockStatus& status) noexcept {
  if (drill_returning_) return run_block(drill_return_, ctx, hold, status);
  if (probe_.moving()) {
    ProbeMovesOfJob moves(*this, ctx, hold, status);
    const DepthProbe::End end = probe_.run(moves, hold_x_, hold_y_, drill_.wear_mm.get());
    if (end.measured) figures_.note_measured(end.depth_mm);
    if (end.over) {
      hold_z_ = pos.z().get();
      drill_returning_ = true;  // back to where the block began, as a rapid
      step_ = Step::kEnter;
    }
    return false;
  }
  hold_position();
  if (step_ == Step::kEnter) {
    drill_return_ = MotionBlock{};
    drill_return_.kind = MotionKind::kRapid;
    drill_return_.line = b.line;
    drill_return_.col = b.col;
    drill_return_.target = {pos.x().get(), pos.y().get(), pos.z().get()};
    figures_.begin_drill_block();
    resumed_wear_mm_ += b.resume_wear_mm;
    const double depth = b.depth_mm > 0.0 ? b.depth_mm : -b.target.z;
    // A resumed hole counts on from its interrupted drill (the rough drilling too).
    const DrillFrom from{.depth_done_mm = b.depth_done_mm,
                         .resume_touch_z_mm = b.resume_touch_z_mm,
                         .resume_wear_mm = b.resume_wear_mm};
    probe_.stop();
    if (probe_.params().enable && manual_.contact.connected()) {
      start_drill(probe_.begin(hold_x_, hold_y_, pos.z().get(), depth), from);
    } else {
      start_drill(depth, from);
    }
    step_ = Step::kBusy;
    return false;
  }
  drill_.start.drive(false);
  set_hold(hold);
  if (drill_.state.get() == kDrilling) probe_.drilling_at(pos.z().get(), false);
  figures_.note_drill(drill_.depth_reached_mm.get(),
                      probe_.wear_before_mm() + drill_.wear_mm.get());
  if (drill_.state.get() != kDone) return false;
  // Retracted out of the hole.
  hold_z_ = pos.z().get();
  if (probe_.drill_done(drill_.wear_mm.get(), drill_.touch_z_mm.get(),
                        drill_.depth_reached_mm.get())) {
    return false;  // the probe's moves follow
  }
  drill_returning_ = true;  // back to where the block began, as a rapid
  step_ = Step::kEnter;
  return false;
}

}  // namespace edm::programs
