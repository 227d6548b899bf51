#pragma once
// MoveInterpolator<Params>: the commands of a move, shared by LinearInterpolator and
// CircularInterpolator (SEEDS 004); the geometry stays in the block. Each cycle, in this order:
//
//   load (level)                 position = the load point, any move cancelled: kOk
//                                (kFault, position kept, when the load point is not finite)
//   rising start edge, not busy  latch a move; a rejected move leaves the block idle: kFault
//   not busy                     v = 0: kOk
//   override not finite          v = 0, no advance: kFault
//   hold                         v = 0, no advance
//   otherwise                    advance by ds = feed/60 · clamp(override, 0, 2) · dt  [mm]
//
// and kSaturated whenever the override was clamped. A rising start edge while busy is ignored.
// `done` is a level: true from the cycle the end is reached until the next move or a load.
//
// The block supplies the geometry through four private hooks (load_position, latch_move, advance,
// publish_at_rest), each RT-safe, and calls reset_move() from its activate().
// RT-safe: update(), enter_safe_state() (cancels the move; the position is kept). Not thread-safe:
// the owning task calls every member except the pins (see pin.hpp).

#include <algorithm>
#include <cmath>
#include <vector>

#include "edm/blocks/rising_edge.hpp"
#include "edm/blocks/validation.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

template <class Params>
class MoveInterpolator : public rt::BlockWithParams<Params> {
 public:
  static constexpr double kMaxOverride = 2.0;

  /// Non-RT. Needs a task period > 0; then activate().
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override {
    dt_s_ = rt::to_seconds(setup.period);
    this->activate();
    return task_period_errors(setup.period);
  }

  /// RT-safe. kOk, kSaturated (override clamped) or kFault (see the file comment).
  rt::BlockStatus update(const rt::CycleContext& /*ctx*/) noexcept final {
    const bool edge = start_edge_(start.get());

    if (load.get()) {
      if (!load_position()) {
        publish_at_rest();
        return rt::BlockStatus::kFault;
      }
      stop_move();
      publish_at_rest();
      return rt::BlockStatus::kOk;
    }
    if (edge && !busy_state_ && !latch_move()) {
      stop_move();
      publish_at_rest();
      return rt::BlockStatus::kFault;
    }
    if (!busy_state_) {
      publish_at_rest();
      return rt::BlockStatus::kOk;
    }

    const double ov_in = feed_override.get();
    if (!std::isfinite(ov_in)) {
      publish_at_rest();
      return rt::BlockStatus::kFault;
    }
    const double ov = std::clamp(ov_in, 0.0, kMaxOverride);
    const rt::BlockStatus status = ov != ov_in ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
    if (hold.get()) {
      publish_at_rest();
      return status;
    }
    advance(feed_mm_s_ * ov * dt_s_);
    return status;
  }

  /// RT-safe. Cancels a move in progress (busy = false, v = 0); the position is kept.
  void enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept final {
    stop_move();
    publish_at_rest();
  }

  // Pins every move has, listed before the block's own.
  rt::Input<bool> start{this->pins_, "start"};
  rt::Input<double> feed_mm_min{this->pins_, "feed_mm_min", "mm/min"};
  rt::Input<double> feed_override{this->pins_, "override", "", 1.0};
  rt::Input<bool> hold{this->pins_, "hold"};
  rt::Input<bool> load{this->pins_, "load"};
  rt::Output<bool> busy{this->pins_, "busy"};
  rt::Output<bool> done{this->pins_, "done"};

 protected:
  /// Non-RT, for the block's activate(): idle, no feed, no start edge seen.
  void reset_move() noexcept {
    feed_mm_s_ = 0.0;
    stop_move();
    start_edge_.reset();
  }
  /// RT-safe, from latch_move(): the move runs at feed [mm/min] from the next advance().
  void begin_move(double feed_mm_min_now) noexcept {
    feed_mm_s_ = feed_mm_min_now / 60.0;
    busy_state_ = true;
    done_state_ = false;
  }
  /// RT-safe: the end is reached (busy = false, done = true).
  void finish_move() noexcept {
    busy_state_ = false;
    done_state_ = true;
  }

  double dt_s_{0.0};  // [s] task period
  bool busy_state_{false};
  bool done_state_{false};

 private:
  void stop_move() noexcept {
    busy_state_ = false;
    done_state_ = false;
  }

  /// Sets the position from the load pins; false (position kept) when one is not finite.
  [[nodiscard]] virtual bool load_position() noexcept = 0;
  /// Latches a move from the pins, then begin_move() or finish_move(); false when rejected.
  [[nodiscard]] virtual bool latch_move() noexcept = 0;
  /// Moves ds_mm [mm] further along the path (finish_move() at its end) and publishes v.
  virtual void advance(double ds_mm) noexcept = 0;
  /// Publishes the position, busy and done with v = 0.
  virtual void publish_at_rest() noexcept = 0;

  double feed_mm_s_{0.0};  // [mm/s] latched feed
  RisingEdge start_edge_;
};

}  // namespace edm::blocks
