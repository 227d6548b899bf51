// The operator's feed override (issue 21) on the whole drilling machine: EdmJob scales a feed
// move's speed by it (a 50 % move takes twice as long), never speeds a rapid beyond its programmed
// speed, and scales the drilling feed cap (0 % stops the feed: no depth is gained).
#include <gtest/gtest.h>

#include <vector>

#include "edm/machining/motion_block.hpp"
#include "job_runner.hpp"

namespace edm::test {
namespace {

using machining::MotionBlock;
using machining::MotionKind;

std::vector<MotionBlock> one_move(MotionKind kind) {
  MotionBlock m;
  m.kind = kind;
  m.line = 1;
  m.col = 1;
  m.target = {6.0, 0.0, 5.0};
  m.feed_mm_s = 2.0;  // F120
  MotionBlock end;
  end.kind = MotionKind::kEnd;
  end.line = 2;
  end.col = 1;
  return {m, end};
}

double job_time_s(MotionKind kind, double override_ratio) {
  const JobResult j = run_job(
      1, one_move(kind), {0, 0, 5.0}, "drill-sim.yaml", [](const rt::VariableRegistry&) {},
      [&](rt::Runtime& r) { EXPECT_TRUE(r.machine().set_feed_override(override_ratio)); });
  EXPECT_TRUE(j.finished) << override_ratio;
  return j.time_s;
}

TEST(FeedOverride, AFeedMoveAtHalfOverrideTakesTwiceAsLong) {
  const double full = job_time_s(MotionKind::kLinear, 1.0);
  const double half = job_time_s(MotionKind::kLinear, 0.5);
  const double fast = job_time_s(MotionKind::kLinear, 1.5);
  std::printf("[feed_override] a feed move at F120: 100 %% %.3f s, 50 %% %.3f s, 150 %% %.3f s\n",
              full, half, fast);
  // The move's time scales as 1/override (the settling into position is a few ms of it).
  EXPECT_NEAR(half / full, 2.0, 0.01);
  EXPECT_NEAR(fast / full, 1.0 / 1.5, 0.01);
}

TEST(FeedOverride, RapidsAreNeverSpedBeyondTheirProgrammedSpeed) {
  const double full = job_time_s(MotionKind::kRapid, 1.0);
  const double fast = job_time_s(MotionKind::kRapid, 1.5);
  const double half = job_time_s(MotionKind::kRapid, 0.5);
  EXPECT_NEAR(fast, full, 0.002) << "150 % on a rapid is 100 %";
  EXPECT_GT(half, full + 0.05) << "below 100 % a rapid slows down";
}

}  // namespace
}  // namespace edm::test
