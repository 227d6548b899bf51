// WallFinish sequence on a synthetic plant (x, y integrate the velocity
// commands): polarity switch before the generator, orbit radius growth per
// revolution (eq. 20–21) up to exactly the final offset, return to the centre,
// safe state.

#include "edm/programs/wall_finish.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "edm/programs/register.hpp"
#include "finish_rig.hpp"
#include "support/param_access.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using programs::WallFinish;

struct FinishRig : FinishInputsRig {
  WallFinish& wf{block};

  explicit FinishRig(const programs::WallFinishParams& p) : FinishInputsRig(p) {
    // orbit.kr keeps WallFinish's default 1e-4 mm/µs: Td = 10 µs → Δr = 1 µm per revolution.
    EXPECT_TRUE(write_param(wf, "orbit.dr_max_mm", rt::ParamValue::of_real(0.005)).empty());
    configure_and_activate();
    x_mm.set(3.0);
    y_mm.set(-2.0);
  }
  bool positive() { return out<bool>("polarity_positive"); }
  double offset() { return out<double>("offset_mm"); }
  double r() { return std::hypot(x_mm.get() - 3.0, y_mm.get() + 2.0); }
  // Sparks at a constant Td while the generator is on.
  void step(double td_us = 10.0) {
    if (gen()) {
      sparks(10, td_us);
    } else {
      sparks(0, 0.0);
    }
    wf.update(ctx);
    x_mm.set(x_mm.get() + out<double>("vx_cmd_mm_s") * ctx.dt_s);
    y_mm.set(y_mm.get() + out<double>("vy_cmd_mm_s") * ctx.dt_s);
    ++ctx.cycle;
    ctx.release += 1ms;
  }
};

programs::WallFinishParams params() {
  programs::WallFinishParams p;
  p.feed_default_mm_min = 20.0;  // ≈ 0.2 s a revolution at the 0.0105 mm final offset
  p.radial_speed_mm_s = 0.05;
  p.spark_out_revs = 2;
  return p;
}

TEST(WallFinish, RegisteredAsAProgramType) { EXPECT_TRUE(is_builtin_program("WallFinish")); }

TEST(WallFinish, RejectsBadParameters) {
  programs::WallFinishParams p = params();
  p.feed_default_mm_min = 0.0;
  p.spark_out_revs = -1;
  EXPECT_EQ(rt::validate_params(p).size(), 2u);
  programs::WallFinish wf;
  wf.set_params(params());
  EXPECT_EQ(write_param(wf, "pol.settle", rt::ParamValue::of_duration(rt::Duration::zero())).size(),
            1u);
  EXPECT_EQ(write_param(wf, "orbit.dr_max_mm", rt::ParamValue::of_real(-1.0)).size(), 1u);
}

TEST(WallFinish, FullCyclePolarityThenGrowingOrbitThenBackToCentre) {
  FinishRig rig(params());
  rig.final_offset.set(0.0105);  // not a multiple of Δr: the last step is cut to land on it
  for (int k = 0; k < 50; ++k) rig.step();
  EXPECT_EQ(rig.state(), 0);
  EXPECT_FALSE(rig.gen());
  EXPECT_FALSE(rig.positive());
  rig.start.set(true);

  bool saw_polarity_state = false;
  std::int64_t switch_cycle = -1;
  std::int64_t first_gen_cycle = -1;
  std::vector<double> offsets;  // orbit offset after each revolution
  std::int64_t revs = 0;
  double max_r_err = 0.0;  // |r − offset| while orbiting on radius
  std::int64_t k = 0;
  for (; k < 40000 && rig.state() != 4; ++k) {
    const bool was_positive = rig.positive();
    rig.step();
    if (rig.state() == 1) saw_polarity_state = true;
    if (!was_positive && rig.positive()) switch_cycle = k;
    if (rig.gen() && first_gen_cycle < 0) first_gen_cycle = k;
    if (rig.gen()) {
      ASSERT_TRUE(rig.positive()) << "generator on with negative polarity at cycle " << k;
    }
    const auto revs_now = rig.out<std::int64_t>("revolutions");
    if (revs_now != revs) {
      revs = revs_now;
      offsets.push_back(rig.offset());
    }
    if (rig.state() == 2 && rig.out<double>("rho_mm") == rig.offset() && revs >= 1) {
      max_r_err = std::max(max_r_err, std::abs(rig.r() - rig.offset()));
    }
  }
  ASSERT_EQ(rig.state(), 4) << "not DONE";
  EXPECT_TRUE(rig.out<bool>("done"));
  EXPECT_TRUE(saw_polarity_state);
  ASSERT_GE(switch_cycle, 0);
  ASSERT_GE(first_gen_cycle, 0);
  // The polarity switched first, and the generator stayed off for the settle
  // time (20 ms).
  EXPECT_GE(first_gen_cycle - switch_cycle, 20);

  // Eq. 20–21: +1 µm per revolution (kr·Tdm = 1e-4 · 10), the last step cut to
  // 0.5 µm, then spark_out_revs revolutions at the final offset.
  ASSERT_GE(offsets.size(), 13u);
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_NEAR(offsets[i], 0.001 * static_cast<double>(i + 1), 1e-12) << i;
  }
  EXPECT_EQ(offsets[10], 0.0105);  // exactly the final offset
  EXPECT_EQ(offsets.size(), 13u);  // 11 growth revolutions + 2 spark-out
  EXPECT_EQ(offsets[11], 0.0105);
  EXPECT_EQ(offsets[12], 0.0105);
  EXPECT_EQ(rig.offset(), 0.0105);
  std::printf("[wall_finish] max |r - offset| while orbiting: %.3f um\n", max_r_err * 1e3);
  EXPECT_LT(max_r_err, 0.001);

  // Back at the centre, generator off, axes stopped, polarity stays positive.
  EXPECT_LE(rig.r(), 0.002);
  EXPECT_FALSE(rig.gen());
  EXPECT_TRUE(rig.positive());
  EXPECT_EQ(rig.out<double>("vx_cmd_mm_s"), 0.0);
  EXPECT_EQ(rig.out<double>("vy_cmd_mm_s"), 0.0);
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_EQ(rig.state(), 4);
}

// Seed 004 Fig. 1: the orbit is the circular interpolator's circle (eq. 14–19) at the orbit feed
// fr, plus the radial compensation. On the final radius R_b the reference moves at fr along the
// circle, and the feed_mm_min input (G160's F through EdmJob) replaces the parameter.
TEST(WallFinish, OrbitReferenceRunsAtTheFeedOnTheFinalRadius) {
  for (const double feed_in : {0.0, 45.0}) {
    FinishRig rig(params());  // feed_default_mm_min 20
    rt::Output<double> feed;
    feed.set(feed_in);
    rig.in<double>("feed_mm_min").connect(feed);
    rig.start_offset.set(0.02);
    rig.final_offset.set(0.02);  // no growth: R_b = ρ = 0.02 mm from the first revolution
    rig.start.set(true);
    const double fr_mm_s = (feed_in > 0.0 ? feed_in : 20.0) / 60.0;
    double px = 0.0, py = 0.0, max_dev = 0.0;
    int samples = 0;
    bool have = false;
    for (int k = 0; k < 20000 && rig.state() != 3; ++k) {
      rig.step();
      const double xr = rig.in<double>("px.x_ref_mm").get(),
                   yr = rig.in<double>("py.x_ref_mm").get();
      const bool on_radius = rig.state() == 2 && rig.out<double>("rho_mm") == 0.02;
      if (on_radius && have) {
        const double speed = std::hypot(xr - px, yr - py) / 1e-3;  // chord per 1 ms cycle
        max_dev = std::max(max_dev, std::abs(speed - fr_mm_s));
        // The reference lies on the orbit circle about the centre (3, -2).
        EXPECT_NEAR(std::hypot(xr - 3.0, yr + 2.0), 0.02, 1e-12) << k;
        ++samples;
      }
      have = on_radius;
      px = xr;
      py = yr;
    }
    EXPECT_GT(samples, 200) << feed_in;  // the spark-out revolutions
    EXPECT_LT(max_dev, fr_mm_s * 1e-3) << "the path speed is the feed (chord vs arc: 1e-3)";
  }
}

TEST(WallFinish, GrowthPerRevolutionIsClampedToDrMax) {
  FinishRig rig(params());
  rig.final_offset.set(0.012);
  rig.start.set(true);
  std::vector<double> offsets;
  std::int64_t revs = 0;
  for (int k = 0; k < 20000 && rig.state() != 4; ++k) {
    rig.step(100.0);  // kr·Tdm = 10 µm > dr_max = 5 µm
    const auto revs_now = rig.out<std::int64_t>("revolutions");
    if (revs_now != revs) {
      revs = revs_now;
      offsets.push_back(rig.offset());
    }
  }
  ASSERT_EQ(rig.state(), 4);
  ASSERT_GE(offsets.size(), 3u);
  EXPECT_NEAR(offsets[0], 0.005, 1e-12);
  EXPECT_NEAR(offsets[1], 0.010, 1e-12);
  EXPECT_EQ(offsets[2], 0.012);
}

TEST(WallFinish, StartOffsetIsTheFirstOrbitRadius) {
  FinishRig rig(params());
  rig.start_offset.set(0.02);
  rig.final_offset.set(0.022);
  rig.start.set(true);
  double first_offset = -1.0;
  for (int k = 0; k < 20000 && rig.state() != 4; ++k) {
    rig.step();
    if (rig.state() == 2 && first_offset < 0.0) first_offset = rig.offset();
  }
  ASSERT_EQ(rig.state(), 4);
  EXPECT_EQ(first_offset, 0.02);
  EXPECT_EQ(rig.offset(), 0.022);
}

TEST(WallFinish, SafeStateStopsAtOnceAndIgnoresStart) {
  FinishRig rig(params());
  rig.final_offset.set(0.05);
  rig.start.set(true);
  for (int k = 0; k < 1000; ++k) rig.step();
  ASSERT_EQ(rig.state(), 2);
  ASSERT_TRUE(rig.gen());
  rig.wf.enter_safe_state(rt::SafeStateRequest{});
  EXPECT_FALSE(rig.gen());
  EXPECT_EQ(rig.out<double>("vx_cmd_mm_s"), 0.0);
  EXPECT_EQ(rig.out<double>("vy_cmd_mm_s"), 0.0);
  EXPECT_EQ(rig.state(), 0);
  rig.ctx.state = rt::MachineState::kFault;
  rig.start.set(false);
  rig.step();
  rig.start.set(true);
  for (int k = 0; k < 100; ++k) rig.step();
  EXPECT_EQ(rig.state(), 0);
  EXPECT_FALSE(rig.gen());
  EXPECT_FALSE(rig.out<bool>("done"));
}

}  // namespace
}  // namespace edm::test
