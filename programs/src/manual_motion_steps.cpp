// ManualMotion's step machine: one cycle of the running operation (jog, home, touch), and the
// sequencing of a touch's sides. Requests, lifecycle and the axes' references are in
// manual_motion.cpp.
#include <cmath>

#include "edm/programs/manual_motion.hpp"

namespace edm::programs {
namespace {

using rt::ManualError;
using rt::ManualOp;
using rt::TouchTarget;

// In position: every axis within this of its reference (the encoder's quantum) for this many
// consecutive cycles (or at most kSettleLimit of manual_motion.cpp after the reference arrived).
constexpr double kInPositionMm = 0.001;
constexpr int kInPositionCycles = 5;

}  // namespace

void ManualMotion::advance(const rt::CycleContext& ctx) noexcept {
  const double dt = dt_s_;
  switch (step_) {
    case Step::kIdle: break;
    case Step::kJog:
      step_profile(dt);
      if (req_.op == ManualOp::kJogVelocity && req_.value != 0.0 &&
          ctx.release - refreshed_ > params_.deadman) {
        // Dead-man: decelerate to a stop from where the reference is.
        const double v = prof_.vel;
        prof_.target = prof_.pos + std::copysign(v * v / (2.0 * params_.accel_mm_s2), v);
        req_.value = 0.0;
        status_.result.error = ManualError::kDeadman;
      }
      if (prof_.done) {
        const ManualError e = status_.result.error;
        finish_settled(e == ManualError::kNone, e, ctx);
      }
      break;
    case Step::kHomeOff:
      if (switch_on(axis_)) {
        if (prof_.done)
          begin_move(axis_, prof_.pos - params_.home_search_max_mm, params_.home_search_mm_s);
        step_profile(dt);
        if (std::abs(prof_.pos - travel_from_) > params_.home_search_max_mm) {
          finish(false, ManualError::kNoSwitch, ctx);
        }
      } else {
        stop_now();
        begin_move(axis_, prof_.pos + params_.home_search_max_mm, params_.home_search_mm_s);
        step_ = Step::kHomeSearch;
      }
      break;
    case Step::kHomeSearch:
      if (switch_on(axis_)) {
        stop_now();
        begin_move(axis_, prof_.pos - params_.home_back_off_mm, params_.home_search_mm_s);
        step_ = Step::kHomeBack;
      } else {
        step_profile(dt);
        if (prof_.done) finish(false, ManualError::kNoSwitch, ctx);
      }
      break;
    case Step::kHomeBack:
      step_profile(dt);
      if (prof_.done) {
        if (switch_on(axis_)) {
          finish(false, ManualError::kNoSwitch, ctx);  // it did not release: a stuck switch
        } else {
          begin_move(axis_, prof_.pos + 2.0 * params_.home_back_off_mm, params_.home_latch_mm_s);
          step_ = Step::kHomeLatch;
        }
      }
      break;
    case Step::kHomeLatch:
      if (switch_on(axis_)) {
        stop_now();
        const double v = axis_ == 0   ? params_.home_x_mm
                         : axis_ == 1 ? params_.home_y_mm
                                      : params_.home_z_mm;
        pos_value[static_cast<std::size_t>(axis_)].set(v);
        pos_set[static_cast<std::size_t>(axis_)].set(true);
        settle_cycles_ = 0;
        step_ = Step::kHomeSettle;
      } else {
        step_profile(dt);
        if (prof_.done) finish(false, ManualError::kNoSwitch, ctx);
      }
      break;
    case Step::kHomeSettle:
      // The driver sets the encoder at the end of the latch cycle; the reading jumps in the
      // next. Still meanwhile; then every reference restarts from the new readings.
      if (++settle_cycles_ >= 2) {
        manual_->bump_position_epoch();
        manual_->set_referenced(axis_);
        for (int k = 0; k < 3; ++k) hold_[k] = axis_mm(k);
        stop_now();
        next_home_axis(ctx);
      } else if (settle_cycles_ == 1) {
        manual_->bump_position_epoch();  // the reading has jumped: restart the supervisor's model
      }
      break;
    case Step::kInPosition: {
      // The mechanics follow the reference with a lag: the operation ends when every axis has
      // stood within kInPositionMm of its reference for kInPositionCycles (or after
      // kSettleLimit, whichever is first), so a jog's distance or a touch's return is exact.
      bool in = std::abs(prof_.pos - axis_mm(axis_)) <= kInPositionMm;
      for (int k = 0; k < 3; ++k) {
        if (k != axis_) in = in && std::abs(hold_[k] - axis_mm(k)) <= kInPositionMm;
      }
      settle_cycles_ = in ? settle_cycles_ + 1 : 0;
      if (settle_cycles_ >= kInPositionCycles || ctx.release >= settle_until_) {
        finish(pending_ok_, pending_error_, ctx);
      }
      break;
    }
    case Step::kTouchArm:
      // The driver switches to touch mode at the end of the first cycle; the contact it senses
      // reads from the next.
      if (++settle_cycles_ >= 2) {
        if (contact.get()) {
          finish(false, ManualError::kAlreadyInContact, ctx);
        } else {
          begin_touch_side();
        }
      }
      break;
    case Step::kTouchFast:
      if (contact.get()) {
        stop_now();
        begin_move(axis_, prof_.pos - side_ * params_.touch_back_off_mm, params_.touch_fast_mm_s);
        step_ = Step::kTouchBack;
      } else {
        step_profile(dt);
        if (prof_.done) {  // no contact within touch_max_mm: back to the start, fail
          begin_move(axis_, start_[axis_], params_.touch_fast_mm_s);
          status_.result.error = ManualError::kNoContact;
          step_ = Step::kReturn;
        }
      }
      break;
    case Step::kTouchBack:
      step_profile(dt);
      if (prof_.done && !contact.get()) {
        begin_move(axis_, prof_.pos + side_ * 2.0 * params_.touch_back_off_mm,
                   params_.touch_slow_mm_s);
        step_ = Step::kTouchSlow;
      }
      break;
    case Step::kTouchSlow:
      if (contact.get()) {
        found_ = axis_mm(axis_);
        stop_now();
        begin_move(axis_, prof_.pos - side_ * params_.touch_back_off_mm, params_.touch_fast_mm_s);
        step_ = Step::kTouchOff;
      } else {
        step_profile(dt);
        if (prof_.done) {
          begin_move(axis_, start_[axis_], params_.touch_fast_mm_s);
          status_.result.error = ManualError::kNoContact;
          step_ = Step::kReturn;
        }
      }
      break;
    case Step::kTouchOff:
      step_profile(dt);
      if (prof_.done) {
        if (req_.target == TouchTarget::kCenter) {
          next_touch(ctx);
        } else {  // every single touch ends back at its start point
          begin_move(axis_, start_[axis_], params_.touch_fast_mm_s);
          step_ = Step::kReturn;
        }
      }
      break;
    case Step::kReturn:
      step_profile(dt);
      if (prof_.done) {
        if (status_.result.error != ManualError::kNone) {
          finish_settled(false, status_.result.error, ctx);
        } else if (req_.target == TouchTarget::kCenter && touch_index_ < 4) {
          begin_touch_side();
        } else {
          next_touch(ctx);
        }
      }
      break;
    case Step::kCentre:
      step_profile(dt);
      if (prof_.done) {
        if (touch_index_ >= 4) {
          finish_settled(true, ManualError::kNone, ctx);
          const double radius = 0.5 * params_.electrode_d_mm;
          status_.result.x = 0.5 * (contact_[0] + contact_[1]);
          status_.result.y = 0.5 * (contact_[2] + contact_[3]);
          status_.result.z = pos.z().get();
          // The Y pair is touched at the X centre: a true diameter (the X pair may be a chord).
          status_.result.size = (contact_[2] + radius) - (contact_[3] - radius);
        } else {
          begin_touch_side();
        }
      }
      break;
  }
}

void ManualMotion::begin_touch_side() noexcept {
  TouchTarget t = req_.target;
  if (t == TouchTarget::kCenter) {
    t = touch_index_ == 0   ? TouchTarget::kXPlus
        : touch_index_ == 1 ? TouchTarget::kXMinus
        : touch_index_ == 2 ? TouchTarget::kYPlus
                            : TouchTarget::kYMinus;
  }
  // The axis each one-sided touch moves and its direction toward the work (z, x+, x-, y+, y-).
  static constexpr int kAxisOf[] = {2, 0, 0, 1, 1};
  static constexpr int kSideOf[] = {-1, 1, -1, 1, -1};
  const auto i = static_cast<std::size_t>(t);  // kCenter became one of the four sides above
  const int a = kAxisOf[i];
  side_ = kSideOf[i];
  const double from = a == axis_ ? prof_.pos : hold_[a];
  start_[a] = from;
  begin_move(a, from + side_ * params_.touch_max_mm, params_.touch_fast_mm_s);
  step_ = Step::kTouchFast;
}

void ManualMotion::next_touch(const rt::CycleContext& ctx) noexcept {
  const double r = 0.5 * params_.electrode_d_mm;
  if (req_.target != TouchTarget::kCenter) {
    finish_settled(true, ManualError::kNone, ctx);
    status_.result.x = pos.x().get();
    status_.result.y = pos.y().get();
    status_.result.z = pos.z().get();
    switch (req_.target) {
      case TouchTarget::kZ: status_.result.z = found_; break;
      case TouchTarget::kXPlus: status_.result.x = found_ + r; break;
      case TouchTarget::kXMinus: status_.result.x = found_ - r; break;
      case TouchTarget::kYPlus: status_.result.y = found_ + r; break;
      case TouchTarget::kYMinus: status_.result.y = found_ - r; break;
      case TouchTarget::kCenter: break;
    }
    return;
  }
  contact_[touch_index_] = found_;
  ++touch_index_;
  if (touch_index_ == 1 || touch_index_ == 3) {  // back to the start, then the other side
    begin_move(axis_, start_[axis_], params_.touch_fast_mm_s);
    step_ = Step::kReturn;
  } else if (touch_index_ == 2 || touch_index_ == 4) {  // to the centre of the two contacts
    begin_move(axis_, 0.5 * (contact_[touch_index_ - 2] + contact_[touch_index_ - 1]),
               params_.touch_fast_mm_s);
    step_ = Step::kCentre;
  }
}

}  // namespace edm::programs
