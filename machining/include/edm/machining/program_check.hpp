#pragma once
// Checks a whole interpreted part program against a machine's tables: the one validation both the
// HMI (`edmhmi check`, before upload) and the runtime (at `program.commit`, before the atomic
// swap) run, so a program the HMI accepts is a program the runtime accepts.
// Non-RT; pure function.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::machining {

struct ProgramIssue {
  std::size_t block{0};  // index into the program
  int line{0};           // the block's G-code line (0 = unknown)
  int col{0};
  std::string message;
};

struct ProgramCheckOptions {
  std::size_t max_blocks{1'000'000};
  double arc_tolerance_mm{0.002};  // |start − centre| vs |end − centre|
  double max_dwell_s{3600.0};
};

/// Every problem found (empty = accepted): non-finite numbers, unknown conditions, end points and
/// arc extremes outside the soft limits, inconsistent arcs, a drill block that does not go down or
/// has no positive travel, an orbit without a positive final radius, negative or huge dwells, an
/// arc before any known position, blocks after the end block, an empty or oversized program.
/// `start` is where the machine is when the program starts (the first block's start point).
std::vector<ProgramIssue> check_program(std::span<const MotionBlock> program,
                                        const MachineTables& tables, const Vec3& start,
                                        const ProgramCheckOptions& options = {});

}  // namespace edm::machining
