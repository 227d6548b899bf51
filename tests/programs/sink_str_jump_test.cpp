// Seed 001's STR on the whole die-sinking machine with the flushing jump
// (config/machines/sink-str-jump-sim.yaml): JumpCycle lifts the electrode every 1.5 s and holds
// the STR (enable = servo_part) through the jump and the 200 ms approach after it. Held so, the
// STR's y_v follows its reference without the bias the approach's open pulses give (B5 in
// docs/benchmarks.md), the z-jitter in the servo part of the cycles stays low, and it machines.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "sim_machine.hpp"
#include "z_jitter.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

class SinkStrJump : public ::testing::TestWithParam<int> {};

TEST_P(SinkStrJump, held_through_the_approach_the_str_tracks_its_reference) {
  VirtualMachine m("sink-str-jump-sim", seeded(GetParam()));
  const rt::PinRef z = m.pin("io.z_mm"), jumping = m.pin("ratios.jump.jumping");
  // The STR's enable is wired from servo_part (read here at the source: the STR's own input is
  // latched at its 50 ms task).
  const rt::PinRef enable = m.pin("ratios.jump.servo_part"), y_v = m.pin("adapt.str.y_v"),
                   y_rv = m.pin("adapt.str.y_rv");

  constexpr std::int64_t kJumpMs = 90, kApproachMs = 200, kCycleMs = 1500;
  std::vector<double> jitter_um, z_end_mm, ts, zs;
  std::int64_t since_jump = -1;  // ms since the last jump's start
  bool was_jumping = false;
  double yv_sum = 0, yr_sum = 0, err_ss = 0, n = 0;
  for (std::int64_t k = 1; k <= 20 * kCycleMs + 200; ++k) {  // 20 whole jumps
    m.run_until(rt::TimePoint{1ms * k});
    ASSERT_FALSE(rt::is_safe_state(m.runtime->machine().state())) << "at " << k << " ms";
    const bool j = rt::read_pin_as_double(jumping) != 0.0;
    if (j && !was_jumping) {  // a jump starts: close the cycle before it
      jitter_um.push_back(rms_about_line(ts, zs) * 1000.0);
      z_end_mm.push_back(zs.empty() ? 0.0 : zs.back());
      ts.clear(), zs.clear();
      since_jump = 0;
    }
    was_jumping = j;
    if (since_jump >= 0) ++since_jump;
    // The STR is held from the jump's start to 200 ms after its end, and only then.
    const bool held = since_jump >= 1 && since_jump <= kJumpMs + kApproachMs;
    ASSERT_EQ(rt::read_pin_as_double(enable) == 0.0, held) << "at " << k << " ms";
    if (since_jump < 0 || since_jump > kJumpMs + kApproachMs) {  // the servo part
      ts.push_back(static_cast<double>(k) * 1e-3);
      zs.push_back(rt::read_pin_as_double(z));
      // One STR sample per 50 ms whose ratio window lies wholly in the servo part, from the
      // third cycle on (the estimator has settled).
      if (jitter_um.size() >= 3 && k % 50 == 0 && since_jump > kJumpMs + kApproachMs + 50) {
        const double yv = rt::read_pin_as_double(y_v), yr = rt::read_pin_as_double(y_rv);
        yv_sum += yv, yr_sum += yr, err_ss += (yv - yr) * (yv - yr), n += 1;
      }
    }
  }
  ASSERT_EQ(jitter_um.size(), 20u) << "a jump every 1.5 s";
  ASSERT_GT(n, 200);
  const double yv_mean = yv_sum / n, yr_mean = yr_sum / n, rms = std::sqrt(err_ss / n);
  double jitter = 0;
  for (std::size_t c = 3; c < jitter_um.size(); ++c) jitter += jitter_um[c];
  jitter /= static_cast<double>(jitter_um.size() - 3);
  std::printf(
      "[sink_str] seed %d: y_v %.3f y_rv %.3f RMS %.3f; jitter %.2f um (cycles 3-19); "
      "z %.4f -> %.4f mm\n",
      GetParam(), yv_mean, yr_mean, rms, jitter, z_end_mm[3], z_end_mm.back());
  EXPECT_NEAR(yv_mean, yr_mean, 0.02) << "no bias from the approach";
  EXPECT_LT(rms, 0.04);
  EXPECT_GT(yr_mean, 0.9) << "the reference decision found the gap good";
  EXPECT_LT(jitter, 2.5) << "Us is not pushed around after every jump";
  EXPECT_LT(z_end_mm.back(), z_end_mm[3] - 0.1) << "and it machines";
}

INSTANTIATE_TEST_SUITE_P(Seeds, SinkStrJump, ::testing::Values(1, 2));

}  // namespace
}  // namespace edm::test
