#pragma once
// Run from a block (docs/gcode.md "Resuming a program"): from an interpreted program, a new
// program that re-approaches the chosen block safely and runs the rest.
//
//   prologue  1. rapid straight up to the clearance Z (the highest Z the program reached before
//                the block, counting where it started, and at least the block's start Z)
//             2. rapid in X/Y to the block's start point, at the clearance Z
//             3. rapid down to the block's start point
//             4. the modal state the program had there: M03/M05, M08/M09, then E (re-arms the
//                generator); rapids never discharge, and the condition comes after them
//   then      the program's blocks from the chosen one on; a drilling block on the chosen line
//             gets depth_done_mm and the Z travel of eq. (9)-(11) for the depth still to erode.
//
// Non-RT; a pure function (thread-safe to call concurrently).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::hmi {

/// The interrupted drill's own state (status job.last: touch_z_mm, wear_mm): with it the resumed
/// drill counts the depth on from its original touch point and wear, and the prologue lowers the
/// electrode, generator off, to kResumeClearanceMm above where the front stopped — inside the
/// hole, first sparks may strike the wall far above the bottom.
struct DrillResume {
  double touch_z_mm{0.0};  // machine Z where the interrupted drill first touched
  double wear_mm{0.0};     // the wear it had compensated since (> 0)
};
inline constexpr double kResumeClearanceMm = 0.2;

struct ResumePlan {
  std::vector<machining::MotionBlock> blocks;  // prologue + the program from `first` on
  std::vector<BlockFrame> frames;              // one per block
  std::size_t first{0};              // index, in the original program, of the first block resumed
  std::size_t prologue{0};           // blocks before it in `blocks`
  std::int32_t line{0};              // the source line of blocks[prologue]
  std::optional<std::size_t> drill;  // index in `blocks` of the drilling block on that line
  double depth_done_mm{0.0};         // what that drilling block was given
  double clearance_z_mm{0.0};        // machine coordinates
  std::string error;                 // non-empty: nothing to resume, say why

  [[nodiscard]] bool ok() const noexcept { return error.empty(); }
};

/// Where each block starts (machine coordinates): program.start_mm for the first, then the point
/// after the block before it (a block's target, except a drilling block, which ends at its start).
std::vector<machining::Vec3> block_starts(const GcodeResult& program);

/// The program resumed at `line` — the G-code source line, as `edmhmi check` and an editor number
/// them: the first block whose line is >= `line`. `depth_done_mm` (>= 0, from the work surface) is
/// the depth the hole of the drilling block on that line already has; it must be 0 when the line
/// has no drilling block. program.start_mm is taken as where the electrode is now (the job runner
/// interprets with the machine's position). `tables` give eq. (10)'s wear and area ratios.
/// Errors: a program with errors, line < 1, a line past the last block or at the program end, a
/// G160 orbit on that line (it cannot be resumed part-way), a depth out of range.
ResumePlan plan_resume(const GcodeResult& program, const machining::MachineTables& tables,
                       std::int32_t line, double depth_done_mm = 0.0,
                       const std::optional<DrillResume>& drill_state = std::nullopt);

}  // namespace edm::hmi
