#include "edm/programs/depth_probe.hpp"

#include <algorithm>

namespace edm::programs {

void DepthProbeParams::visit(rt::ParamVisitor& v) {
  v.param("enable", enable,
          {"",
           "measure a blind hole's depth by touch (bottom and surface) and drill the rest from the "
           "measurement"});
  v.param("margin_mm", margin_mm,
          {"mm",
           "the first drilling stops this much short of the depth (more than the wear estimate's "
           "error)",
           rt::open_closed(0.0, 5.0)});
  v.param("dx_mm", dx_mm,
          {"mm", "X of the surface touch relative to the hole (on the work)",
           rt::closed(-100.0, 100.0)});
  v.param("dy_mm", dy_mm,
          {"mm", "Y of the surface touch relative to the hole (on the work)",
           rt::closed(-100.0, 100.0)});
  v.param("clear_mm", clear_mm,
          {"mm", "a probe touch starts this far above the expected contact",
           rt::open_closed(0.0, 5.0)});
}

void DepthProbe::activate() noexcept {
  set_step(kOff);
  moving_ = false;
  failures.set(0);
  measured_depth_mm.set(0.0);
}

void DepthProbe::set_step(std::int64_t s) noexcept {
  step_ = s;
  step.set(s);
}

void DepthProbe::stop() noexcept {
  set_step(kOff);
  moving_ = false;
  fallback_ = false;
  wear_rough_ = 0.0;
}

double DepthProbe::begin(double x, double y, double z_start, double depth_mm) noexcept {
  // The rough drilling stops short by the margin (half the depth of a very shallow hole).
  const double m = params_.margin_mm;
  wear_rough_ = 0.0;
  moving_ = false;
  fallback_ = false;
  depth_mm_ = depth_mm;
  rough_mm_ = depth_mm > 2.0 * m ? depth_mm - m : 0.5 * depth_mm;
  x_ = x;
  y_ = y;
  z_start_ = z_start;
  set_step(kRough);
  return rough_mm_;
}

void DepthProbe::drilling_at(double z, bool started) noexcept {
  z_low_ = started ? z : std::min(z_low_, z);
}

bool DepthProbe::drill_done(double wear_mm, double touch_z_mm, double reached_mm) noexcept {
  if (step_ == kRough) {
    wear_rough_ = wear_mm;
    rough_touch_z_ = touch_z_mm;
    rough_reached_ = reached_mm;
    set_step(kToBottom);
    return true;
  }
  if (step_ == kFinish && !fallback_) {
    set_step(kToBottom2);
    return true;
  }
  set_step(kOff);
  return false;
}

void DepthProbe::failed() noexcept {
  failures.set(failures.get() + 1);
  fallback_ = true;
  set_step(kUpHere);
}

bool DepthProbe::rapid(ProbeMoves& m, double x, double y, double z) noexcept {
  const bool arrived = m.rapid(x, y, z, !moving_);
  moving_ = !arrived;
  return arrived;
}

bool DepthProbe::touch(ProbeMoves& m, bool& ok, double& z) noexcept {
  const bool ended = m.touch(!moving_, ok, z);
  moving_ = !ended;
  return ended;
}

DepthProbe::End DepthProbe::run(ProbeMoves& moves, double hold_x, double hold_y,
                                double drill_wear_mm) noexcept {
  const double clear = params_.clear_mm;
  const double sx = x_ + params_.dx_mm, sy = y_ + params_.dy_mm;
  bool ok = false;
  double z = 0.0;
  End end;
  switch (step_) {
    case kToBottom:
      if (rapid(moves, x_, y_, z_low_ + clear)) set_step(kTouchBottom);
      break;
    case kTouchBottom:
      if (touch(moves, ok, z)) {
        if (!ok) {
          failed();
          break;
        }
        z_b_ = z;
        set_step(kUp);
      }
      break;
    case kUp:
      if (rapid(moves, x_, y_, z_start_)) set_step(kOver);
      break;
    case kOver:
      if (rapid(moves, sx, sy, z_start_)) set_step(kToSurface);
      break;
    case kToSurface: {
      const double expected = z_b_ + rough_mm_;
      if (rapid(moves, sx, sy, std::min(z_start_, expected + clear))) set_step(kTouchSurface);
      break;
    }
    case kTouchSurface:
      if (touch(moves, ok, z)) {
        if (!ok) {
          failed();
          break;
        }
        d1_ = z - z_b_;
        set_step(kUpHere);
      }
      break;
    case kUpHere:
      if (rapid(moves, hold_x, hold_y, z_start_)) set_step(kBack);
      break;
    case kBack:
      if (rapid(moves, x_, y_, z_start_)) set_step(kIntoHole);
      break;
    case kIntoHole: {
      const double to = fallback_ ? z_low_ + clear : z_b_ + clear;
      if (!rapid(moves, x_, y_, to)) break;
      DrillFrom from;
      if (fallback_) {  // on from the rough drilling's touch point and wear
        from.depth_done_mm = rough_reached_;
        from.resume_touch_z_mm = rough_touch_z_;
        from.resume_wear_mm = wear_rough_;
        wear_rough_ = 0.0;  // the resumed drill's wear includes it
      } else {              // on from the measured bottom
        from.contact_z_mm = z_b_;
        from.contact_depth_mm = d1_;
      }
      moves.drill(depth_mm_, from);
      set_step(kFinish);
      break;
    }
    case kToBottom2:
      if (rapid(moves, x_, y_, z_low_ + clear)) set_step(kTouchBottom2);
      break;
    case kTouchBottom2:
      if (!touch(moves, ok, z)) break;
      if (ok) {
        // One electrode between the two bottom contacts, shortened by the finish's wear.
        const double d = d1_ + (z_b_ - z) - drill_wear_mm;
        measured_depth_mm.set(d);
        end.measured = true;
        end.depth_mm = d;
      } else {
        failures.set(failures.get() + 1);
      }
      set_step(kOff);
      end.over = true;
      break;
    default: break;
  }
  return end;
}

}  // namespace edm::programs
