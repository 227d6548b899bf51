// Seed 004 eq. (9)-(11): off-line wear pre-compensation.
#include "edm/machining/wear_precomp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::machining {
namespace {

TEST(WearPrecomp, DeltaIsWearRateTimesMachiningTime) {
  // eq. (9)-(10) written out with explicit rates: MRRw = 2 mm³/s, MRRe = θ·MRRw, A = 0.5 mm².
  const double lz = 20.0, theta = 0.6, mrr_w = 2.0, area = 0.5;
  const double tw = machining_time_s(lz, mrr_w, area);
  EXPECT_DOUBLE_EQ(tw, lz * area / mrr_w);
  const double vd = theta * mrr_w / area;  // eq. (8)
  const WearPrecomp p = wear_precompensate(lz, theta);
  EXPECT_NEAR(p.delta_mm, vd * tw, 1e-12);
  EXPECT_NEAR(p.travel_mm, lz + vd * tw, 1e-12);  // eq. (11)
}

TEST(WearPrecomp, NoWearMeansNoChangeAndBadInputIsPassedThrough) {
  EXPECT_EQ(wear_precompensate(5.0, 0.0).travel_mm, 5.0);
  EXPECT_EQ(wear_precompensate(5.0, -1.0).travel_mm, 5.0);
  EXPECT_EQ(wear_precompensate(5.0, std::numeric_limits<double>::quiet_NaN()).delta_mm, 0.0);
  EXPECT_EQ(machining_time_s(5.0, 0.0, 1.0), 0.0);
}

TEST(MotionKind, NamesRoundTrip) {
  for (int i = 0; i < kMotionKindCount; ++i) {
    const auto k = static_cast<MotionKind>(i);
    MotionKind back{};
    ASSERT_TRUE(motion_kind_from_string(to_string(k), back)) << i;
    EXPECT_EQ(back, k);
  }
  MotionKind out{};
  EXPECT_FALSE(motion_kind_from_string("warp", out));
}

TEST(MachineTables, LookupByNumberAndAxis) {
  MachineTables t;
  t.conditions.push_back({.e = 2, .name = "finish"});
  t.axes.push_back({.name = 'Z', .min_mm = -60, .max_mm = 20});
  ASSERT_NE(t.condition(2), nullptr);
  EXPECT_EQ(t.condition(2)->name, "finish");
  EXPECT_EQ(t.condition(1), nullptr);
  ASSERT_NE(t.axis('Z'), nullptr);
  EXPECT_EQ(t.axis('X'), nullptr);
}

}  // namespace
}  // namespace edm::machining
