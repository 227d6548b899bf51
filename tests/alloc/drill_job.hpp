#pragma once
// The jobs the allocation tests run: the drill's (a rapid over the hole, E1, M08 when asked, a
// 5 mm deep drilling, 8 mm of Z travel, the end) and the wire machine's cut.

#include <vector>

#include "edm/machining/motion_block.hpp"

namespace edm::test {

inline std::vector<machining::MotionBlock> drill_job(bool flushing = false) {
  using machining::MotionBlock;
  using machining::MotionKind;
  std::vector<MotionBlock> job;
  job.reserve(5);  // the references below stay valid
  MotionBlock& rapid = job.emplace_back();
  rapid.kind = MotionKind::kRapid;
  rapid.target = {0, 0, 0.1};
  MotionBlock& condition = job.emplace_back();
  condition.kind = MotionKind::kCondition;
  condition.condition = 1;
  if (flushing) {
    MotionBlock& m08 = job.emplace_back();
    m08.kind = MotionKind::kFlushing;
    m08.on = true;
  }
  MotionBlock& drill = job.emplace_back();
  drill.kind = MotionKind::kDrill;
  drill.target = {0, 0, -5};
  drill.condition = 1;
  drill.z_travel_mm = 8;
  job.emplace_back().kind = MotionKind::kEnd;
  return job;
}

/// The wire machine's (wire-sim.yaml): from its start hole a rapid close to the hole's wall, E1,
/// a cut in +X into the plate, and round a corner (a cut arc), the end.
inline std::vector<machining::MotionBlock> wire_job() {
  using machining::MotionBlock;
  using machining::MotionKind;
  std::vector<MotionBlock> job(5);
  job[0].kind = MotionKind::kRapid;
  job[0].target = {-8.66, 0, 0};
  job[1].kind = MotionKind::kCondition;
  job[1].condition = 1;
  job[2].kind = MotionKind::kLinear;
  job[2].target = {-8.4, 0, 0};
  job[2].condition = 1;
  job[2].cut = true;
  job[2].feed_mm_s = 0.05;
  job[3] = job[2];
  job[3].kind = MotionKind::kArcCw;
  job[3].centre = {-8.4, -0.2, 0};
  job[3].target = {-8.2, -0.2, 0};
  job[4].kind = MotionKind::kEnd;
  return job;
}

}  // namespace edm::test
