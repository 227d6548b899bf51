// EdmJob's drilling blocks: the drill child's cycle, and the depth probe that measures a blind
// hole's depth by touch (edm_job.hpp, docs/blocks.md "The depth probe").
#include <algorithm>
#include <cmath>

#include "edm/programs/edm_job.hpp"

namespace edm::programs {
namespace {
using machining::MotionBlock;
using machining::MotionKind;

// The probe's steps (output probe_step).
enum Probe : std::int64_t {
  kOff = 0,
  kRough = 1,         // the drill to depth − margin
  kToBottom = 2,      // rapid into the hole, probe_clear_mm above where the drilling stopped
  kTouchBottom = 3,   // touch −Z: the bottom's contact z_b
  kUp = 4,            // rapid up to the block's start Z
  kOver = 5,          // rapid to the surface's touch point
  kToSurface = 6,     // rapid down to probe_clear_mm above the expected contact
  kTouchSurface = 7,  // touch −Z: the surface's contact z_s; d1 = z_s − z_b
  kUpHere = 8,        // rapid up to the block's start Z where the axes are
  kBack = 9,          // rapid over the hole
  kIntoHole = 10,     // rapid down to probe_clear_mm above the bottom's contact
  kFinish = 11,       // the drill from the contact to the depth
  kToBottom2 = 12,    // rapid down to probe_clear_mm above where the finish stopped
  kTouchBottom2 = 13  // touch −Z: the depth measured
};

constexpr auto kDone = static_cast<std::int64_t>(DeepHoleDrill::State::kDone);
constexpr auto kDrilling = static_cast<std::int64_t>(DeepHoleDrill::State::kDrill);

}  // namespace

void EdmJob::set_probe(std::int64_t step) noexcept {
  probe_ = step;
  probe_step.set(step);
}

void EdmJob::start_drill(double depth_mm) noexcept {
  drill_depth_mm.set(depth_mm);
  drill_start.set(true);
  probe_z_low_ = z_mm.get();
}

bool EdmJob::run_drill(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                       rt::BlockStatus& status) noexcept {
  if (drill_returning_) return run_block(drill_return_, ctx, hold, status);
  if (probe_ != kOff && probe_ != kRough && probe_ != kFinish) {
    run_probe(ctx, hold, status);
    return false;
  }
  hold_position();
  if (step_ == Step::kEnter) {
    drill_return_ = MotionBlock{};
    drill_return_.kind = MotionKind::kRapid;
    drill_return_.line = b.line;
    drill_return_.col = b.col;
    drill_return_.target = {x_mm.get(), y_mm.get(), z_mm.get()};
    figures_.begin_drill_block();
    const double depth = b.depth_mm > 0.0 ? b.depth_mm : -b.target.z;
    drill_depth_done_mm.set(b.depth_done_mm);
    drill_resume_touch_z_mm.set(b.resume_touch_z_mm);
    drill_resume_wear_mm.set(b.resume_wear_mm);
    drill_contact_z_mm.set(0.0);
    drill_contact_depth_mm.set(0.0);
    probe_wear_rough_ = 0.0;
    set_probe(kOff);
    probe_moving_ = false;
    probe_fallback_ = false;
    if (params_.probe_depth && manual_.contact.connected()) {
      // The rough drilling stops short by the margin (half the depth of a very shallow hole).
      const double m = params_.probe_margin_mm;
      probe_depth_mm_ = depth;
      probe_rough_mm_ = depth > 2.0 * m ? depth - m : 0.5 * depth;
      probe_x_ = hold_x_;
      probe_y_ = hold_y_;
      probe_z_start_ = z_mm.get();
      set_probe(kRough);
      start_drill(probe_rough_mm_);
    } else {
      start_drill(depth);
    }
    step_ = Step::kBusy;
    return false;
  }
  drill_start.set(false);
  feed_hold.set(hold);
  if (drill_.state.get() == kDrilling) probe_z_low_ = std::min(probe_z_low_, z_mm.get());
  figures_.note_drill(drill_.depth_reached_mm.get(), probe_wear_rough_ + drill_.wear_mm.get());
  if (drill_.state.get() != kDone) return false;
  // Retracted out of the hole.
  hold_z_ = z_mm.get();
  if (probe_ == kRough) {
    probe_wear_rough_ = drill_.wear_mm.get();
    probe_rough_touch_z_ = drill_.touch_z_mm.get();
    probe_rough_reached_ = drill_.depth_reached_mm.get();
    set_probe(kToBottom);
    return false;
  }
  if (probe_ == kFinish && !probe_fallback_) {
    set_probe(kToBottom2);
    return false;
  }
  set_probe(kOff);
  drill_returning_ = true;  // back to where the block began, as a rapid
  step_ = Step::kEnter;
  return false;
}

bool EdmJob::probe_rapid(double x, double y, double z, const rt::CycleContext& ctx, bool hold,
                         rt::BlockStatus& status) noexcept {
  if (!probe_moving_) {
    probe_move_ = MotionBlock{};
    probe_move_.kind = MotionKind::kRapid;
    probe_move_.line = drill_return_.line;
    probe_move_.col = drill_return_.col;
    probe_move_.target = {x, y, z};
    step_ = Step::kEnter;
    probe_moving_ = true;
  }
  if (!run_linear(probe_move_, ctx, hold, status)) return false;
  probe_moving_ = false;
  step_ = Step::kBusy;
  return true;
}

bool EdmJob::probe_touch(const rt::CycleContext& ctx, bool& ok, double& z) noexcept {
  // The touch drives the axes; the loops follow where they are (no error builds up in them).
  hold_x_ = x_mm.get();
  hold_y_ = y_mm.get();
  hold_z_ = z_mm.get();
  hold_position();
  if (!probe_moving_) {
    if (!manual_.begin_job_touch_z(ctx)) {
      ok = false;
      return true;
    }
    probe_moving_ = true;
    return false;
  }
  if (manual_.job_touch_busy()) return false;
  probe_moving_ = false;
  ok = manual_.job_touch_ok();
  z = manual_.job_touch_z_mm();
  return true;
}

void EdmJob::run_probe(const rt::CycleContext& ctx, bool hold, rt::BlockStatus& status) noexcept {
  const double clear = params_.probe_clear_mm;
  const double sx = probe_x_ + params_.probe_dx_mm, sy = probe_y_ + params_.probe_dy_mm;
  bool ok = false;
  double z = 0.0;
  // A touch that found nothing: the rest is drilled on the estimate, as a resumed hole.
  const auto failed = [this] {
    probe_failures.set(probe_failures.get() + 1);
    probe_fallback_ = true;
    set_probe(kUpHere);
  };
  switch (probe_) {
    case kToBottom:
      if (probe_rapid(probe_x_, probe_y_, probe_z_low_ + clear, ctx, hold, status)) {
        set_probe(kTouchBottom);
      }
      break;
    case kTouchBottom:
      if (probe_touch(ctx, ok, z)) {
        if (!ok) {
          failed();
          break;
        }
        probe_z_b_ = z;
        set_probe(kUp);
      }
      break;
    case kUp:
      if (probe_rapid(probe_x_, probe_y_, probe_z_start_, ctx, hold, status)) set_probe(kOver);
      break;
    case kOver:
      if (probe_rapid(sx, sy, probe_z_start_, ctx, hold, status)) set_probe(kToSurface);
      break;
    case kToSurface: {
      const double expected = probe_z_b_ + probe_rough_mm_;
      if (probe_rapid(sx, sy, std::min(probe_z_start_, expected + clear), ctx, hold, status)) {
        set_probe(kTouchSurface);
      }
      break;
    }
    case kTouchSurface:
      if (probe_touch(ctx, ok, z)) {
        if (!ok) {
          failed();
          break;
        }
        probe_d1_ = z - probe_z_b_;
        set_probe(kUpHere);
      }
      break;
    case kUpHere:
      if (probe_rapid(hold_x_, hold_y_, probe_z_start_, ctx, hold, status)) set_probe(kBack);
      break;
    case kBack:
      if (probe_rapid(probe_x_, probe_y_, probe_z_start_, ctx, hold, status)) {
        set_probe(kIntoHole);
      }
      break;
    case kIntoHole: {
      const double to = probe_fallback_ ? probe_z_low_ + clear : probe_z_b_ + clear;
      if (!probe_rapid(probe_x_, probe_y_, to, ctx, hold, status)) break;
      hold_position();
      if (probe_fallback_) {  // on from the rough drilling's touch point and wear
        drill_depth_done_mm.set(probe_rough_reached_);
        drill_resume_touch_z_mm.set(probe_rough_touch_z_);
        drill_resume_wear_mm.set(probe_wear_rough_);
        probe_wear_rough_ = 0.0;  // the resumed drill's wear includes it
      } else {                    // on from the measured bottom
        drill_depth_done_mm.set(0.0);
        drill_resume_touch_z_mm.set(0.0);
        drill_resume_wear_mm.set(0.0);
        drill_contact_z_mm.set(probe_z_b_);
        drill_contact_depth_mm.set(probe_d1_);
      }
      start_drill(probe_depth_mm_);
      set_probe(kFinish);
      break;
    }
    case kToBottom2:
      if (probe_rapid(probe_x_, probe_y_, probe_z_low_ + clear, ctx, hold, status)) {
        set_probe(kTouchBottom2);
      }
      break;
    case kTouchBottom2:
      if (!probe_touch(ctx, ok, z)) break;
      if (ok) {
        // One electrode between the two bottom contacts, shortened by the finish's wear.
        const double d = probe_d1_ + (probe_z_b_ - z) - drill_.wear_mm.get();
        measured_depth_mm.set(d);
        figures_.note_measured(d);
      } else {
        probe_failures.set(probe_failures.get() + 1);
      }
      set_probe(kOff);
      hold_z_ = z_mm.get();
      drill_returning_ = true;  // back to where the block began, as a rapid
      step_ = Step::kEnter;
      break;
    default:
      break;
  }
}

}  // namespace edm::programs
