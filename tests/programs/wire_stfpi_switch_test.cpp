// Bumpless switching on the whole wire machine (config/machines/wire-stfpi-sim.yaml): the
// operator switches the self-tuning fuzzy controller off (fixed settings, 30 µs / 50 V) and on
// again with `var.write rupture.sel_u.select false|true` while the simulated wire cuts.
//   off: the applied commands ramp from the controller's last values to the fixed ones over the
//        Select's 2 s ramp (no step larger than one ramp increment), then hold them exactly;
//        meanwhile the idle controller tracks what is applied;
//   on:  the controller starts from the applied fixed settings: the first step is one
//        controller increment, not a jump back to where it was before it was switched off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

TEST(WireStfpiSwitch, the_operator_switches_controller_and_fixed_settings_without_a_bump) {
  VirtualMachine m("wire-stfpi-sim");
  auto& vars = m.vars();
  auto pin = [&](const char* name) { return m.pin(name); };
  const rt::PinRef applied_u = pin("io.arc_off_time_us"), applied_v = pin("io.servo_ref_v");
  const rt::PinRef pi_u = pin("rupture.pi.arc_off_time_us"), pi_v = pin("rupture.pi.servo_ref_v");
  const rt::PinRef broken = pin("io.wire_broken");
  constexpr double kFixedU = 30.0, kFixedV = 50.0, kRampS = 2.0, kSampleS = 0.04;
  std::int64_t k = 0;  // 40 ms samples of the rupture task
  auto step = [&] {
    ++k;
    m.run_until(rt::TimePoint{40ms * k});
    return std::pair{rt::read_pin_as_double(applied_u), rt::read_pin_as_double(applied_v)};
  };
  auto [u, v] = step();
  while (k < 250) {  // 10 s under the controller: it has moved off its 20 µs / 40 V start
    std::tie(u, v) = step();
  }
  ASSERT_EQ(rt::read_pin_as_double(broken), 0.0);
  ASSERT_GT(std::fabs(u - kFixedU), 1.0) << "the test needs a bump to ramp away";
  EXPECT_EQ(u, rt::read_pin_as_double(pi_u)) << "the controller's command is applied";
  EXPECT_EQ(v, rt::read_pin_as_double(pi_v));

  // Off: the ramp takes the bump b away in equal steps of b·T/ramp_time.
  ASSERT_TRUE(vars.write("rupture.sel_u.select", rt::ParamValue::of_bool(false)));
  const double max_du = std::fabs(u - kFixedU) * kSampleS / kRampS * 1.0001;
  const double max_dv = std::fabs(v - kFixedV) * kSampleS / kRampS * 1.0001 + 1e-12;
  for (int i = 0; i < 100; ++i) {  // 4 s: the 2 s ramp and 2 s of fixed settings
    const auto [u1, v1] = step();
    EXPECT_LE(std::fabs(u1 - u), max_du) << "sample " << i;
    EXPECT_LE(std::fabs(v1 - v), max_dv) << "sample " << i;
    u = u1;
    v = v1;
  }
  EXPECT_EQ(u, kFixedU) << "after the ramp the fixed settings are applied exactly";
  EXPECT_EQ(v, kFixedV);
  EXPECT_EQ(rt::read_pin_as_double(pi_u), kFixedU) << "the idle controller tracks them";
  EXPECT_EQ(rt::read_pin_as_double(pi_v), kFixedV);

  // On: the controller continues from the applied settings. One increment of eq. 4-5 is
  // |dU|·Ku·|e|·Φ·Ψ with |dU| ≤ 1, |e| ≤ 1, Φ ≤ 1: far below the bump of the first switch.
  ASSERT_TRUE(vars.write("rupture.sel_u.select", rt::ParamValue::of_bool(true)));
  const double bump_before = max_du * kRampS / kSampleS;
  const auto [u2, v2] = step();
  EXPECT_LT(std::fabs(u2 - kFixedU), 0.1 * bump_before) << "no jump back to the old command";
  EXPECT_EQ(u2, rt::read_pin_as_double(pi_u)) << "the controller's command is applied at once";
  EXPECT_EQ(v2, rt::read_pin_as_double(pi_v));
}

}  // namespace
}  // namespace edm::test
