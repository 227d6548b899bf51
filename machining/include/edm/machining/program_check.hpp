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
  bool soft_limit{false};  // a point of the block (end, arc or orbit extent, drill travel) is
                           // beyond a soft limit
  char axis{0};  // 'X'/'Y'/'Z' when an end point (or drill travel) is beyond that axis's limit,
                 // so a G-code reader can point at the axis word; 0 for extents and other issues
};

struct ProgramCheckOptions {
  std::size_t max_blocks{1'000'000};
  double arc_tolerance_mm{0.002};  // |start − centre| vs |end − centre|
  double max_dwell_s{3600.0};
  /// The electrode length now (rt::Electrode; 0: unknown). A rapid or feed with an
  /// electrode_ref_mm is checked where the job will put it: Z shifted by the length lost since its
  /// work frame's Z was set (the wear of the program's own holes, which lowers it further, is not
  /// known here).
  double electrode_mm{0.0};
};

/// Every problem found (empty = accepted): non-finite numbers, unknown conditions, end points and
/// arc extremes outside the soft limits, inconsistent arcs, a drill block that does not go down or
/// has no positive travel, an orbit without a positive final radius, negative or huge dwells, an
/// arc before any known position, blocks after the end block, an empty or oversized program.
/// `start` is where the machine is when the program starts (the first block's start point).
/// Soft-limit messages read "X 150.000 mm is beyond the X soft limit (-100.000..100.000 mm)",
/// prefixed "G02 arc: " / "G160 orbit of radius R mm: " for extents (docs/gcode.md); each arc
/// reports each axis's extreme once, over its swept angle.
std::vector<ProgramIssue> check_program(std::span<const MotionBlock> program,
                                        const MachineTables& tables, const Vec3& start,
                                        const ProgramCheckOptions& options = {});

}  // namespace edm::machining
