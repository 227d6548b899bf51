#pragma once
// WearCompensator: real-time electrode-wear compensation of the Z feed (SEEDS 004, eq. 8).
//
//   Vd = MRRe / A_e                 electrode length consumed per second            [mm/s]
//   MRRe = wear_ratio · MRRw        wear_ratio = electrode volume / workpiece volume removed
//   MRRw = A_hole · v_bottom        workpiece volume removed per second             [mm³/s]
//   v_bottom ≈ |vz_in|              (drilling down, vz_in < 0)
//   ⇒ Vd = wear_ratio · (A_hole / A_e) · |vz_in|,     vz_out = vz_in − Vd
//
// Estimator: the gap controller's command vz_in is the feed the electrode FRONT needs relative
// to the work to hold the gap. With a steady gap the hole bottom advances at the front's speed, so
// the bottom feed is |vz_in| and the workpiece rate is A_hole·|vz_in|. The front moves at the axis
// feed plus the wear (the electrode shortens at Vd), so commanding the axis vz_in − Vd makes the
// front move at exactly vz_in.
// No compensation (vz_out = vz_in, Vd = 0) while vz_in ≥ 0 (holding or retracting: no erosion
// progress is made) or while enable is false.
// wear_mm accumulates Vd·dt (forward Euler, the length compensated so far). Its state is the
// output pin itself, as in Integrator: a retained value restored into it is where accumulation
// continues. configure() and reset_wear = true set it to 0; activate() leaves it alone.
// wear_ratio is clamped to [0, wear_ratio_max] (kSaturated when cut).
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
  double wear_ratio_max{5.0};  // [-] upper clamp for the wear_ratio input

  void visit(rt::ParamVisitor& v) {
    v.param("hole_area_mm2", hole_area_mm2, "mm^2", "cross-section of the hole A_hole (> 0)");
    v.param("electrode_area_mm2", electrode_area_mm2, "mm^2",
            "cross-section of the electrode material A_e (> 0; a tube: pi/4*(D^2-d^2))");
    v.param("wear_ratio_max", wear_ratio_max, "", "upper clamp of the wear_ratio input (> 0)");
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class WearCompensator final : public rt::BlockWithParams<WearCompensatorParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override;
  /// Non-RT. Needs a task period > 0. Sets wear_mm = 0.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// RT-safe. kOk, kSaturated (wear_ratio clamped) or kFault (non-finite input or state).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 protected:
  void params_changed() noexcept override;

 private:
  void compute_ratio() noexcept;

  rt::Input<double> vz_in_mm_s_;
  rt::Input<double> wear_ratio_;
  rt::Input<bool> enable_{true};
  rt::Input<bool> reset_wear_;
  rt::Output<double> vz_out_mm_s_;
  rt::Output<double> vd_mm_s_;
  rt::Output<double> wear_mm_;
  double dt_s_{0.0};
  double area_ratio_{1.0};  // A_hole / A_e
};

}  // namespace edm::blocks
