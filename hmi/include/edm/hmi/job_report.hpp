#pragma once
// What edmhmi shows of a job: the figures it reads from edmplc's status, the live progress line
// and the final job report (docs/hmi.md). The figures come from the runtime (EdmJob's job_*
// outputs, the I/O driver's io.* pins, named in the machine config's bridge.status_vars), so a
// report is the machine's account of the job, also when the HMI was restarted in between.
//
// A status variable is found by the end of its name, so any program/block naming works:
//   *.job_time_s *.job_pulses *.job_shorts *.job_arcs *.job_depth_mm *.job_wear_mm
//   io.depth_mm (hole depth, simulator) io.electrode_mm io.wall_radius_mm io.x_mm io.y_mm io.z_mm
//
// Non-RT; pure functions and plain data (thread-compatible).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "edm/bridge/codec.hpp"
#include "edm/hmi/work_offsets.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::hmi {

/// The job figures of one status snapshot; absent when the config does not publish them.
struct JobFigures {
  std::optional<double> time_s, pulses, shorts, arcs, depth_mm, wear_mm;
  std::optional<double> hole_depth_mm, electrode_mm, wall_radius_mm;
  std::optional<double> x_mm, y_mm, z_mm;
  /// The job's electrode length compensation of its last move (cnc.job.z_comp_mm): the spindle
  /// Z is the tip's plus this, so the tip in work coordinates is machine − offset − this.
  std::optional<double> z_comp_mm;

  [[nodiscard]] std::optional<double> short_fraction() const;
  [[nodiscard]] std::optional<double> arc_fraction() const;
};

JobFigures figures_from_status(const bridge::StatusMessage& s);

/// A drilled hole of the program: where (both coordinate systems) and how deep.
struct HolePosition {
  std::int32_t line{0};
  machining::Vec3 machine_mm{};  // the drilling block's target: X, Y and the nominal bottom Z
  machining::Vec3 work_mm{};     // the same in its work frame
  std::uint8_t frame{0};         // 0 = G54 .. 5 = G59
  double depth_mm{0.0};          // below the work surface (MotionBlock::depth_mm)
};

/// A drilling block's depth below the work surface: depth_mm, or −target.z for a block made
/// without work offsets (depth_mm 0, machine Z 0 the surface).
double drill_depth_of(const machining::MotionBlock& b) noexcept;

/// What the program asked for, from its motion blocks.
struct ProgramTargets {
  std::size_t blocks{0};
  double deepest_drill_mm{0.0};     // max drill_depth_of() of the drilling blocks (0: none)
  double largest_radius_mm{0.0};    // max final_radius_mm of the orbit-finishing blocks (0: none)
  std::vector<HolePosition> holes;  // with frames only: each drilling block, in order
  std::optional<BlockFrame> end_frame;  // with frames only: the frame of the last block
};
ProgramTargets program_targets(const std::vector<machining::MotionBlock>& blocks);
/// With the work frame of each block (GcodeResult::frames, same size as `blocks`): also the
/// holes and the frame at the end, for the report's work and machine coordinates.
ProgramTargets program_targets(const std::vector<machining::MotionBlock>& blocks,
                               const std::vector<BlockFrame>& frames);

/// The live view the progress line is drawn from.
struct ProgressView {
  std::string state;        // machine state
  std::string outcome;      // job outcome
  std::uint64_t block{0};   // index of the block being executed
  std::uint64_t blocks{0};  // blocks in the program
  std::int32_t line{0};
  machining::MotionKind kind{machining::MotionKind::kEnd};  // of the current block, if known
  double drill_target_mm{0.0};  // of the current drilling block (0: not drilling)
  double elapsed_s{0.0};
  std::optional<double> eta_s;
  JobFigures figures;
};

/// One line (no newline): a bar of `bar_width` cells over the hole depth while drilling, else
/// over the blocks, then numbers, elapsed time, ETA and the state.
std::string format_progress(const ProgressView& v, int bar_width = 24);

/// "X 1.2500 Y -3.0000 Z 0.0000" (mm, 4 decimals; a value that rounds to 0 prints as 0, not -0).
std::string format_xyz(const machining::Vec3& v);

/// "1:02:03" / "2:03" style.
std::string format_duration(double seconds);

struct JobReport {
  std::string part;
  std::string machine;
  std::string outcome;  // finished, aborted, ...
  std::string state;    // machine state at the end
  int cause{0};         // alarm code of the last entry into a safe state
  ProgramTargets targets;
  std::uint64_t blocks_done{0};
  JobFigures end;                               // the last status of the job
  std::optional<double> electrode_at_start_mm;  // io.electrode_mm before cycle.start
  std::vector<std::string> alarms;              // "code name: text" as they came
  int fault_alarms{0};                          // of them, with fault severity
  bool dry_run{false};     // the motion only: nothing was drilled, so no depth error is reported
  bool alarms_seen{true};  // `alarms` were watched during the job (not so for `edmhmi status`,
                           // which has the machine's last cause only: no "alarms none" then)
};

/// The machine's side of a report from one status: outcome, state, the alarm cause (only while in
/// FAULT/ESTOP: an older cause is stale), blocks done (all of them when finished) and the figures.
void fill_from_status(JobReport& r, const bridge::StatusMessage& s);

/// The multi-line report edmhmi prints at the end of `run` (and `status` of a finished job). With
/// the program's frames known it also shows the work frame, each hole (up to kReportHoles) and the
/// end position in work and machine coordinates.
inline constexpr std::size_t kReportHoles = 10;
std::string format_report(const JobReport& r);

}  // namespace edm::hmi
