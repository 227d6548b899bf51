#pragma once
// The G-code interpreter of the HMI (DESIGN §10, docs/gcode.md): part-program text → motion
// blocks in absolute machine coordinates, checked against the machine's condition table and soft
// limits, or every error found as "file:line:col: message". The program is written in work
// coordinates: G54..G59 select one of the machine's work frames (GcodeOptions::offsets, the
// runtime's `offset.get`), G92 adds a program-local offset; machine = work + frame + G92.
//
// Non-RT (allocates). Thread-safety: interpret_gcode() is a pure function of its arguments, so
// concurrent calls are safe; the result types are thread-compatible plain data.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "edm/hmi/work_offsets.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::hmi {

struct GcodeOptions {
  /// Where the electrode tip is when the program starts (machine coordinates, mm). The job runner
  /// fills it from the machine's status; offline checks use the origin.
  machining::Vec3 start_mm{};
  /// The machine's work frames G54..G59 (machine coordinates of each frame's origin). The program
  /// starts in G54; all zero = work coordinates are machine coordinates.
  WorkOffsets offsets{};
  /// MDI: the text need not end with M02/M30; without one an end block is appended.
  bool implicit_end{false};
  /// Feed used by G01/G02/G03, drilling and the orbit cycle before any F word (mm/min); 0 means
  /// "none": the first feed move without an F word is an error.
  double default_feed_mm_min{0.0};
  /// An arc's end must lie on its circle: |r_end − r_start| ≤ max(abs, rel·r_start) (mm).
  double arc_tolerance_mm{0.002};
  double arc_tolerance_rel{1e-4};
  /// G02/G03 P (extra full turns) accepts 0..max_arc_turns.
  int max_arc_turns{1000};
  /// Longer lines are refused (bytes, without the line end).
  std::size_t max_line_length{1024};
  /// After this many errors the interpreter stops with a "too many errors" message.
  std::size_t max_errors{100};
};

/// One problem, located at the offending word (1-based line and column, bytes).
struct GcodeError {
  int line{0};
  int col{0};
  std::string message;
};

struct GcodeResult {
  std::string file;                            // the name used in messages
  std::vector<machining::MotionBlock> blocks;  // empty when errors is not
  std::vector<BlockFrame> frames;              // the work frame of each block (blocks' size)
  machining::Vec3 start_mm{};                  // the start point used (machine coordinates)
  double electrode_mm{0.0};        // the electrode length interpreted with (offsets; 0: unknown)
  std::vector<GcodeError> errors;  // file order (line, then column)
  double drill_depth_mm{0.0};      // Σ nominal lz of the drilling blocks
  double electrode_wear_mm{0.0};   // Σ δ (eq. 10) of the drilling blocks
  int drill_blocks{0};
  int cut_blocks{0};          // wire machines: the cut blocks (compensated) ...
  double cut_length_mm{0.0};  // ... and their path length

  [[nodiscard]] bool ok() const noexcept { return errors.empty(); }
  /// Every error as "file:line:col: message", in file order.
  [[nodiscard]] std::vector<std::string> messages() const;
};

/// Interprets a whole part program. Never throws for bad input (only std::bad_alloc), never
/// loops longer than linear in the input size. `file` is only used in messages.
GcodeResult interpret_gcode(std::string_view text, std::string_view file,
                            const machining::MachineTables& tables,
                            const GcodeOptions& options = {});

}  // namespace edm::hmi
