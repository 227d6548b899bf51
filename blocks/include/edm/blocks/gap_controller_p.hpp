#pragma once
// GapControllerP: the proportional gap controller of seed 004, eq. (1), on the ignition delay.
//
//   Vz = Kg·(Tdr − Td)      clamped to [−v_feed_max_mm_s, +v_retract_max_mm_s]
//
// The steady offset (paper-faithful). While the hole deepens at v_b the P law can only command
// Vz = −v_b with an error: Td − Tdr = v_b/Kg (the real-time wear compensator adds its Vd on top,
// so v_b is the bottom's speed alone). On the drill preset (v_b ≈ 0.5 mm/s, Kg 0.05) Td sits near
// 18 µs against Tdr = 8 µs. That is seed 004's controller as published, and the default.
// The standard remedy, an option: an integral term (ki > 0, 0 = the paper's P law),
//   Vz = Kg·(Tdr − Td) + ki·∫(Tdr − Td) dt,
// integrated only while the P law runs (not in retract, hold, disable or while Td is not valid,
// which freeze it) and not while the output is clamped with the error pushing further
// (conditional integration: no wind-up). activate() clears it. docs/benchmarks.md has its row.
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

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct GapControllerPParams {
  double kg{0.05};                 // [mm/s per µs] > 0
  double tdr_default_us{8.0};      // [µs] > 0, used while the tdr_us input is 0 (unwired)
  double v_feed_max_mm_s{1.0};     // [mm/s] > 0, largest downward speed (Vz ≥ −this)
  double v_retract_max_mm_s{5.0};  // [mm/s] > 0, largest upward speed (Vz ≤ +this)
  double retract_speed_mm_s{2.0};  // [mm/s] in (0, v_retract_max_mm_s], Vz while retract
  double idle_feed_mm_s{0.0};      // [mm/s] in [−v_feed_max_mm_s, 0], Vz while valid = false
  double ki{0.0};                  // [mm/s per µs·s] ≥ 0, integral gain (0: the paper's P law)

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): kg up to 10 mm/s per µs of Td error (seed 004 designs Kg ≈ 0.05; at 10 a
    // 1 µs error already saturates any speed limit); Tdr and Td within 10 ms (param_ranges.hpp);
    // ki up to 1e4 (ki/kg = 1/Ti: Ti = 1 ms even at the largest kg, 5 µs at the default one).
    v.param("kg", kg,
            {"mm/s/us", "gain: Vz per microsecond of Td error", rt::open_closed(0.0, 10.0)});
    v.param("tdr_default_us", tdr_default_us,
            {"us", "reference ignition delay while the tdr_us input is 0",
             rt::open_closed(0.0, 10000.0)});
    v.param("v_feed_max_mm_s", v_feed_max_mm_s,
            {"mm/s", "largest downward speed", ranges::kSpeedMmS});
    v.param("v_retract_max_mm_s", v_retract_max_mm_s,
            {"mm/s", "largest upward speed", ranges::kSpeedMmS});
    v.param("retract_speed_mm_s", retract_speed_mm_s,
            {"mm/s", "upward speed while retract, <= v_retract_max_mm_s", ranges::kSpeedMmS});
    v.param("idle_feed_mm_s", idle_feed_mm_s,
            {"mm/s", "speed while no valid Td, >= -v_feed_max_mm_s", rt::closed(-1000.0, 0.0)});
    v.param("ki", ki,
            {"mm/s/(us*s)",
             "integral gain on the Td error; 0 = seed 004's P law (steady Td offset v_b/Kg while "
             "drilling)",
             rt::closed(0.0, 1.0e4)});
  }
  /// Cross-field rules: retract_speed <= v_retract_max, idle_feed >= -v_feed_max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class GapControllerP final : public rt::BlockWithParams<GapControllerPParams> {
 public:
  /// Non-RT. Needs a task period > 0 (the integral's dt).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. vz_mm_s = 0, saturated = false, integral 0.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (clamped), or kFault (broken Td or Tdr while the P law runs).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<double> td_us{pins_, "td_us", "us"};
  rt::Input<bool> valid{pins_, "valid", "", true};
  rt::Input<bool> enable{pins_, "enable", "", true};
  rt::Input<bool> hold{pins_, "hold"};
  rt::Input<bool> retract{pins_, "retract"};
  rt::Input<double> tdr_us{pins_, "tdr_us", "us"};  // 0 (unwired): use the parameter
  rt::Output<double> vz_mm_s{pins_, "vz_mm_s", "mm/s"};
  rt::Output<bool> saturated{pins_, "saturated"};

 private:
  double dt_s_{0.0};
  double integral_us_s_{0.0};  // ∫(Tdr − Td) dt [µs·s]
};

}  // namespace edm::blocks
