#pragma once
// WearCompensator: real-time electrode-wear compensation of the Z feed (SEEDS 004, eq. 8).
//
//   Vd = MRRe / A_e                 electrode length consumed per second            [mm/s]
//   MRRe = wear_ratio · MRRw        wear_ratio = electrode volume / workpiece volume removed
//   MRRw = A_hole · v_bottom        workpiece volume removed per second             [mm³/s]
//   ⇒ Vd = wear_ratio · (A_hole / A_e) · v_bottom,     vz_out = vz_in − Vd
//
// Estimator of v_bottom: the gap controller's command vz_in is the velocity the electrode FRONT
// needs relative to the work to hold the gap (commanding the axis vz_in − Vd makes the front move
// at exactly vz_in, because the electrode shortens at Vd). The front is integrated over the time
// since the previous cycle's release (up to 10 periods; a longer gap is a pause of the block and
// counts as one period), so cycles a loaded real-time machine
// omits — while the axis keeps moving at the last command — still count. The block integrates the
// front position p += vz_in·dt and keeps its deepest point so far (a high-water mark): the hole
// bottom advances only when the front goes deeper than it has ever been,
//   v_bottom·dt = max(0, −p − deepest),   deepest = max(deepest, −p).
// For a steady downward feed this is v_bottom = |vz_in| (eq. 8 exactly); the servo's back-and-
// forth motion over already-eroded depth (short-circuit retracts, gap oscillation at a high Kg)
// removes no material and adds no wear — counting every down-stroke would over-estimate the wear
// in proportion to the oscillation (measured: +11 % at Kg = 0.15 mm/s/µs on the drill preset).
// No compensation while vz_in ≥ 0 or below the high-water mark, or while enable is false (the
// front is still tracked, so enabling later does not count old depth).
// wear_mm accumulates Vd·dt (the length compensated so far). Its state is the output pin itself,
// as in Integrator: a retained value restored into it is where accumulation continues (the front
// and high-water mark restart at 0 there). configure() and reset_wear = true set wear_mm, the
// front and the high-water mark to 0; activate() leaves them alone.
// The area ratio A_hole/A_e is the area_ratio input when it is > 0 (the active condition's, so that
// eq. 8 and the HMI's eq. 10 use one value), else hole_area_mm2/electrode_area_mm2. A non-finite
// area_ratio input: the parameters' ratio for that cycle, kFault.
// While the wear_ratio input is <= 0 (an unwired input reads 0) the parameter wear_ratio_default
// is θ instead (default 0: no compensation without an estimate). θ is clamped to
// [0, wear_ratio_max]; kSaturated when it was cut or the input was negative.
// Non-finite vz_in: vz_out = 0 (stop the axis), kFault. Non-finite wear_ratio: no compensation
// (vz_out = vz_in) for that cycle, kFault — a broken estimate must not stop nor drive the axis.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <numbers>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct WearCompensatorParams {
  // Defaults: a Ø1.1 mm hole drilled with a Ø1.0/Ø0.3 mm tube electrode.
  double hole_area_mm2{std::numbers::pi / 4.0 * 1.1 * 1.1};                     // ≈ 0.9503
  double electrode_area_mm2{std::numbers::pi / 4.0 * (1.0 * 1.0 - 0.3 * 0.3)};  // ≈ 0.7147
  double wear_ratio_max{5.0};      // [-] upper clamp for the wear_ratio input
  double wear_ratio_default{0.0};  // [-] θ while the wear_ratio input is <= 0 (unwired)

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): areas up to 1 m² (a large die-sinking electrode is ~0.25 m²; the drill
    // tube ~0.7 mm²); wear ratios up to 10, the bound of a condition's wear_ratio (machining; PM
    // §2: drills at ~100 V wear >300 %).
    v.param("hole_area_mm2", hole_area_mm2,
            {"mm^2", "cross-section of the hole A_hole", rt::open_closed(0.0, 1.0e6)});
    v.param("electrode_area_mm2", electrode_area_mm2,
            {"mm^2", "cross-section of the electrode material A_e (a tube: pi/4*(D^2-d^2))",
             rt::open_closed(0.0, 1.0e6)});
    v.param("wear_ratio_max", wear_ratio_max,
            {"", "upper clamp of the wear_ratio input", rt::open_closed(0.0, 10.0)});
    v.param("wear_ratio_default", wear_ratio_default,
            {"", "wear ratio used while the wear_ratio input is <= 0 (unwired), <= wear_ratio_max",
             rt::closed(0.0, 10.0)});
  }
  /// Cross-field rule: wear_ratio_default <= wear_ratio_max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class WearCompensator final : public rt::BlockWithParams<WearCompensatorParams> {
 public:
  /// Non-RT. Needs a task period > 0. Sets wear_mm = 0.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// RT-safe. kOk, kSaturated (wear_ratio clamped) or kFault (non-finite input or state).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 protected:
  void params_changed() noexcept override;

 private:
  void compute_ratio() noexcept;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<double> vz_in_mm_s{pins_, "vz_in_mm_s", "mm/s"};
  rt::Input<double> wear_ratio{pins_, "wear_ratio"};
  rt::Input<double> area_ratio{pins_, "area_ratio"};  // ≤ 0 (unwired): the two area parameters
  rt::Input<bool> enable{pins_, "enable", "", true};
  rt::Input<bool> reset_wear{pins_, "reset_wear"};
  rt::Output<double> vz_out_mm_s{pins_, "vz_out_mm_s", "mm/s"};
  rt::Output<double> vd_mm_s{pins_, "vd_mm_s", "mm/s"};
  rt::Output<double> wear_mm{pins_, "wear_mm", "mm"};

 private:
  double dt_s_{0.0};
  double area_ratio_{1.0};    // A_hole / A_e
  double front_mm_{0.0};      // ∫ vz_in dt since the last reset (0 = where the reset happened)
  double deepest_mm_{0.0};    // max(−front_mm_) so far, ≥ 0
  bool have_release_{false};  // last_release_ is valid (not the first cycle since a reset)
  rt::TimePoint last_release_{};
};

}  // namespace edm::blocks
