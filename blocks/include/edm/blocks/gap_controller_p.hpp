#pragma once
// GapControllerP: the proportional gap controller of seed 004, eq. (1), on the ignition delay.
//
//   Vz = Kg·(Tdr − Td)      clamped to [−v_feed_max_mm_s, +v_retract_max_mm_s]
//
// Z is positive upward and the electrode drills downward: a gap that is too large (Td > Tdr)
// gives Vz < 0 (feed down into the work), a gap that is too small (Td < Tdr) gives Vz > 0 (back
// off). Tdr is the input tdr_us when it is > 0 (the active condition sets it), else the
// parameter tdr_default_us (an unwired input reads 0).
//
// Commands, highest precedence first:
//   retract         Vz = +retract_speed_mm_s                    (whatever enable/hold say)
//   enable = false  Vz = 0
//   hold            Vz = 0     (a P controller has no state: releasing hold resumes at once)
//   valid = false   Vz = idle_feed_mm_s   (no ignited pulse in the Td window: gap open, creep)
//   otherwise       the P law above
// saturated is true only when the P law (or the idle feed) was clamped.
//
// Status: kSaturated when clamped, else kOk. A non-finite td_us or tdr_us input, or a negative
// tdr_us input, is a broken signal when the P law needs it: vz_mm_s and saturated are held and
// update() returns kFault. Retract, disable and hold do not read Td, so a broken Td can never block
// a retract. RT-safe: update(). Not thread-safe: the owning task calls every member except the pins
// (see pin.hpp).

#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct GapControllerPParams {
  double kg{0.05};                 // [mm/s per µs] > 0
  double tdr_default_us{8.0};      // [µs] > 0, used while the tdr_us input is 0 (unwired)
  double v_feed_max_mm_s{1.0};     // [mm/s] > 0, largest downward speed (Vz ≥ −this)
  double v_retract_max_mm_s{5.0};  // [mm/s] > 0, largest upward speed (Vz ≤ +this)
  double retract_speed_mm_s{2.0};  // [mm/s] in (0, v_retract_max_mm_s], Vz while retract
  double idle_feed_mm_s{0.0};      // [mm/s] in [−v_feed_max_mm_s, 0], Vz while valid = false

  void visit(rt::ParamVisitor& v) {
    v.param("kg", kg, "mm/s/us", "gain: Vz per microsecond of Td error (> 0)");
    v.param("tdr_default_us", tdr_default_us, "us",
            "reference ignition delay while the tdr_us input is 0 (> 0)");
    v.param("v_feed_max_mm_s", v_feed_max_mm_s, "mm/s", "largest downward speed (> 0)");
    v.param("v_retract_max_mm_s", v_retract_max_mm_s, "mm/s", "largest upward speed (> 0)");
    v.param("retract_speed_mm_s", retract_speed_mm_s, "mm/s",
            "upward speed while retract (> 0, <= v_retract_max_mm_s)");
    v.param("idle_feed_mm_s", idle_feed_mm_s, "mm/s",
            "speed while no valid Td (<= 0, >= -v_feed_max_mm_s)");
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class GapControllerP final : public rt::BlockWithParams<GapControllerPParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override;
  /// Non-RT. vz_mm_s = 0, saturated = false.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (clamped), or kFault (broken Td or Tdr while the P law runs).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  rt::Input<double> td_us_;
  rt::Input<bool> valid_{true};
  rt::Input<bool> enable_{true};
  rt::Input<bool> hold_;
  rt::Input<bool> retract_;
  rt::Input<double> tdr_us_;  // 0 (unwired): use the parameter
  rt::Output<double> vz_mm_s_;
  rt::Output<bool> saturated_;
};

}  // namespace edm::blocks
