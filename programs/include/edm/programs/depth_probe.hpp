#pragma once
// DepthProbe: the machining cycle that measures a blind hole's depth by touch instead of
// estimating it (issue 20 f; docs/blocks.md "The depth probe"). A child of the job sequencer
// (EdmJob's `probe`), which runs a drilling block through it when `enable` is set and touch
// sensing is wired:
//   rough    the drill to depth − margin_mm (eq. 8's estimate);
//   bottom   touch −Z on the hole's bottom: axis Z z_b;
//   surface  up to the block's start Z, over by (dx_mm, dy_mm), touch −Z on the work's
//            surface: z_s; measured depth d1 = z_s − z_b (one electrode, one touch-sensing
//            distance: the wear cancels);
//   finish   back into the hole, the drill from the contact (contact_z_mm = z_b,
//            contact_depth_mm = d1) to the depth;
//   check    touch the bottom again: z_b2; the depth measured,
//            d = d1 + (z_b − z_b2) − the finish's wear (eq. 8 over ≈ margin only)
//            → measured_depth_mm, the job's depth figure.
// A touch that finds nothing (no contact within manual.touch_max_mm, already in contact) ends
// the probe: `failures` counts it and the rest is drilled on the estimate (as a resumed hole),
// so the hole is still finished.
//
// The probe plans; the job moves. Its moves (rapids, touches, drillings) are asked of the job
// through ProbeMoves, so they run on the job's interpolator, loops, drill and manual touch like
// any other block's. update() does nothing: the job calls run() while the probe is between
// drillings. Outputs: step (Step below), measured_depth_mm (the last probed hole's depth, 0:
// none), failures (touches that found nothing).
// RT-safety: every member but configure/visit is RT-safe (no allocation, lock or throw).

#include <cstdint>

#include "edm/runtime/block.hpp"

namespace edm::programs {

struct DepthProbeParams {
  bool enable{false};     // on: drill, touch the bottom and the surface, drill the rest
  double margin_mm{0.1};  // [mm] the first drilling stops this much short of the depth
  double dx_mm{2.0};      // [mm] where the surface is touched, relative to the hole
  double dy_mm{0.0};      // [mm]
  double clear_mm{0.2};   // [mm] a touch starts this far above the expected contact

  void visit(rt::ParamVisitor& v);
};

/// Where a drilling of the probe counts its depth from (DeepHoleDrill's inputs of the same
/// names): a resumed hole (depth_done, resume_*) or a measured bottom (contact_*).
struct DrillFrom {
  double depth_done_mm{0.0};
  double resume_touch_z_mm{0.0};
  double resume_wear_mm{0.0};
  double contact_z_mm{0.0};
  double contact_depth_mm{0.0};
};

/// The moves the probe asks of its job. RT-safe.
class ProbeMoves {
 public:
  /// A rapid to (x, y, z), begun when `begin`, else going on; true once it has arrived.
  virtual bool rapid(double x, double y, double z, bool begin) noexcept = 0;
  /// A −Z touch, begun when `begin`, else going on; true once it has ended (ok: contact at z;
  /// a touch that cannot begin ends at once, not ok).
  virtual bool touch(bool begin, bool& ok, double& z) noexcept = 0;
  /// Holds the axes where they are and starts the drill to `depth_mm`, counting from `from`.
  virtual void drill(double depth_mm, const DrillFrom& from) noexcept = 0;

 protected:
  ~ProbeMoves() = default;
};

class DepthProbe final : public rt::BlockWithParams<DepthProbeParams> {
 public:
  enum Step : std::int64_t {
    kOff = 0,
    kRough = 1,         // the drill to depth − margin
    kToBottom = 2,      // rapid into the hole, clear_mm above where the drilling stopped
    kTouchBottom = 3,   // touch −Z: the bottom's contact z_b
    kUp = 4,            // rapid up to the block's start Z
    kOver = 5,          // rapid to the surface's touch point
    kToSurface = 6,     // rapid down to clear_mm above the expected contact
    kTouchSurface = 7,  // touch −Z: the surface's contact z_s; d1 = z_s − z_b
    kUpHere = 8,        // rapid up to the block's start Z where the axes are
    kBack = 9,          // rapid over the hole
    kIntoHole = 10,     // rapid down to clear_mm above the bottom's contact
    kFinish = 11,       // the drill from the contact to the depth
    kToBottom2 = 12,    // rapid down to clear_mm above where the finish stopped
    kTouchBottom2 = 13  // touch −Z: the depth measured
  };
  /// What run() ended with: the block's probing is over (the job returns to the block's start)
  /// and, if `measured`, the hole's measured depth.
  struct End {
    bool over{false};
    bool measured{false};
    double depth_mm{0.0};
  };

  rt::Output<std::int64_t> step{pins_, "step"};
  rt::Output<double> measured_depth_mm{pins_, "measured_depth_mm", "mm"};
  rt::Output<std::int64_t> failures{pins_, "failures"};

  void activate() noexcept override;
  rt::BlockStatus update(const rt::CycleContext& /*ctx*/) noexcept override {
    return rt::BlockStatus::kOk;
  }

  /// A drilling block at (x, y, z_start) to `depth_mm` begins with the probe: the depth of the
  /// rough drilling the job starts now.
  double begin(double x, double y, double z_start, double depth_mm) noexcept;
  /// A drilling of the probe starts at axis Z `z` / runs at `z` (the lowest is kept).
  void drilling_at(double z, bool started) noexcept;
  /// The drill is done. True when the probe goes on (its moves, run()); false when the block's
  /// drilling is over. `wear_mm`, `touch_z_mm`, `reached_mm`: the drill's outputs.
  bool drill_done(double wear_mm, double touch_z_mm, double reached_mm) noexcept;
  /// One cycle of the moves between the drillings. `hold_x`, `hold_y`: where the job holds the
  /// axes; `drill_wear_mm`: the drill's wear output (the finish's).
  End run(ProbeMoves& moves, double hold_x, double hold_y, double drill_wear_mm) noexcept;
  /// Off: the job ended (finished, aborted), or a drilling block runs without the probe.
  void stop() noexcept;

  [[nodiscard]] bool active() const noexcept { return step_ != kOff; }
  /// Between the drillings: the job calls run() instead of running the drill.
  [[nodiscard]] bool moving() const noexcept {
    return step_ != kOff && step_ != kRough && step_ != kFinish;
  }
  /// The rough drilling's wear, added to the finish's for the job's wear figure.
  [[nodiscard]] double wear_before_mm() const noexcept { return wear_rough_; }

 private:
  void set_step(std::int64_t s) noexcept;
  void failed() noexcept;
  bool rapid(ProbeMoves& m, double x, double y, double z) noexcept;
  bool touch(ProbeMoves& m, bool& ok, double& z) noexcept;

  std::int64_t step_{kOff};
  bool moving_{false};    // a rapid or touch has started
  bool fallback_{false};  // a touch failed: the rest is drilled on the estimate
  double x_{0.0}, y_{0.0}, z_start_{0.0};
  double depth_mm_{0.0};  // the block's depth
  double rough_mm_{0.0};  // the rough drilling's depth
  double z_low_{0.0};     // the lowest axis Z of the drilling that ran last
  double z_b_{0.0};       // the bottom's contact
  double d1_{0.0};        // the depth measured before the finish
  double wear_rough_{0.0};
  double rough_touch_z_{0.0};
  double rough_reached_{0.0};
};

}  // namespace edm::programs
