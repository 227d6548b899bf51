#pragma once
// The job the allocation tests drill with: a rapid over the hole, E1, M08 when asked, a 5 mm
// deep drilling (8 mm of Z travel), the end.

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

}  // namespace edm::test
