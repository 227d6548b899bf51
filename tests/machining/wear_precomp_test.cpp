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

TEST(WearPrecomp, DeltaUsesEq8sAreaRatioWhenTheHoleIsWiderThanTheElectrode) {
  // Vd = MRRe/A_e (eq. 8) while the hole bottom advances at MRRw/A_hole, so the machining time of
  // lz is lz·A_hole/MRRw (eq. 9): δ = θ·(A_hole/A_e)·lz. A Ø1.0/0.3 tube in a Ø1.1 hole.
  const double a_e = 0.25 * 3.141592653589793 * (1.0 - 0.09);
  const double a_hole = 0.25 * 3.141592653589793 * 1.21;
  const double lz = 12.0, theta = 0.6, mrr_w = 3.5;
  const double vd = theta * mrr_w / a_e;
  const double tw = machining_time_s(lz, mrr_w, a_hole);
  const WearPrecomp p = wear_precompensate(lz, theta, a_hole / a_e);
  EXPECT_NEAR(p.delta_mm, vd * tw, 1e-12);
  EXPECT_NEAR(p.travel_mm, lz + vd * tw, 1e-12);
  // The one-area form (area ratio 1) under-plans this electrode's wear by A_hole/A_e.
  EXPECT_NEAR(p.delta_mm / wear_precompensate(lz, theta).delta_mm, 1.21 / 0.91, 1e-12);
}

TEST(WearPrecomp, NoWearMeansNoChangeAndBadInputIsPassedThrough) {
  EXPECT_EQ(wear_precompensate(5.0, 0.0).travel_mm, 5.0);
  EXPECT_EQ(wear_precompensate(5.0, -1.0).travel_mm, 5.0);
  EXPECT_EQ(wear_precompensate(5.0, std::numeric_limits<double>::quiet_NaN()).delta_mm, 0.0);
  EXPECT_EQ(wear_precompensate(5.0, 0.6, 0.0).travel_mm, 5.0);
  EXPECT_EQ(wear_precompensate(5.0, 0.6, -2.0).delta_mm, 0.0);
  EXPECT_EQ(wear_precompensate(5.0, 0.6, std::numeric_limits<double>::infinity()).delta_mm, 0.0);
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
