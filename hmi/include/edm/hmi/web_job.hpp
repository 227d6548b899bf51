#pragma once
// The job that `edmhmi serve` owns on behalf of every browser (docs/web.md): the part program
// text, its interpretation against the machine's own tables (machine.info) and work offsets
// (offset.get), the upload, the start (also as a dry run, or from a line: resume.hpp), an MDI
// line (mdi.hpp, the runtime's MDI slot), and the job report built from the runtime's figures
// when the job ends.
//
// The job lives here and in edmplc, never in a browser: a page that reloads, sleeps or closes
// changes nothing; a new page is sent snapshot() and carries on.
//
// Non-RT. Thread-safe: every public member locks one mutex. check(), upload(), start() make
// blocking bridge requests: call them from the server's worker thread, never from the I/O thread
// or a bridge event handler. on_status() / on_alarm() are cheap and may be called from the
// client's event thread.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/hmi/job_report.hpp"
#include "edm/hmi/work_offsets.hpp"
#include "edm/machining/machine_tables.hpp"

namespace edm::hmi {

/// Largest part program a browser may send (bytes of G-code text).
inline constexpr std::size_t kMaxWebProgramBytes = std::size_t{2} << 20;
/// Most points of the toolpath preview sent to a browser (longer paths are thinned).
inline constexpr std::size_t kMaxToolpathPoints = 20000;

class WebJob {
 public:
  explicit WebJob(bridge::Client& client) : client_(client) {}

  /// machine.info: the tables every check and upload uses. Returns false (and why) on failure.
  bool refresh_machine(std::string& error);
  /// {"name", "axes", "conditions", "condition_edit"} as machine.info gave them (null before
  /// refresh_machine()).
  [[nodiscard]] bridge::Json machine_info() const;
  /// machine.info as edmplc sent it (also "ops" and "manual"; null before refresh_machine()).
  [[nodiscard]] bridge::Json machine_info_raw() const;

  /// offset.get: the work frames every interpretation uses from now on. False (and why) when
  /// refused; an edmplc without the op (unknown_op) leaves them zero and returns true.
  bool refresh_offsets(std::string& error);
  /// {"frames": {"G54": {"x","y","z"}, …}, "generation"} of the last offset.get (null: none).
  [[nodiscard]] bridge::Json offsets_json() const;

  /// Interprets `text` against the machine's tables from the current position, nothing sent.
  /// {"ok", "errors": [{"line","col","message"}], "blocks", "drill_blocks", "drill_depth_mm",
  ///  "electrode_wear_mm"}.
  bridge::Json check(const std::string& text, const std::string& name);
  /// check(), then program.begin/chunk/commit. {"ok", ...} or {"ok": false, "code", "message",
  /// "errors"} (interpreter errors or the commit's issues, located at their lines).
  bridge::Json upload(const std::string& text, const std::string& name);
  /// cycle.start of the committed program (electrode length noted for the report); a dry run
  /// keeps the generator off (cycle.start {"dry_run": true}).
  bridge::Reply start(bool dry_run = false);
  /// Run from a line (resume.hpp): the loaded program interpreted again from where the electrode
  /// is, with the current offsets, resumed at source line `line` (a safe re-approach first),
  /// committed in place of the loaded program, and started. The drilling block on that line goes
  /// on from `depth_done_mm`, else from the runtime's record of the last job when it ended on
  /// that line (status job.last: its depth, and its touch Z and wear so the drill counts on from
  /// them, as `edmhmi run --from`), else from 0. {"ok", "line", "first_block", "prologue",
  /// "depth_done_mm", "depth_from", "clearance_z_mm", "blocks"} or {"ok": false, "code",
  /// "message", "errors"?}.
  bridge::Json start_from(std::int32_t line, std::optional<double> depth_done_mm, bool dry_run);
  /// MDI: one line interpreted from where the electrode is (mdi.hpp), committed to the runtime's
  /// MDI slot and started there; the loaded program and its report stay as they are. {"ok",
  /// "blocks"} or {"ok": false, "code", "message", "errors"?}.
  bridge::Json mdi(const std::string& line);

  /// Status and alarm events of the server's own bridge session.
  void on_status(const bridge::StatusMessage& s);
  void on_alarm(const bridge::Json& alarm_event);

  /// What a browser needs to show the job: {"part", "text", "generation", "blocks",
  /// "toolpath": [[x,y,z],…], "frames": [[first block, frame 0..5, ox, oy, oz], …] (the work
  /// frame from each block on, G92 included: the page's work coordinates during the job),
  /// "resumed_from": line | null, "drills": [[block, line, depth_mm], …] (each drilling block:
  /// the page's depth bar and ETA), "dry_run" (the job started as one), "report": null |
  /// {"text", "outcome", …}}.
  [[nodiscard]] bridge::Json snapshot() const;

 private:
  std::optional<machining::Vec3> position_locked() const;
  /// The G-code interpreted against a copy of the tables and offsets from the current position
  /// (returned in options.start_mm), outside the lock; nullopt before refresh_machine().
  /// `generation`: the offset.get generation of the offsets used (absent: no offsets op).
  std::optional<GcodeResult> interpret(const std::string& text, const std::string& name,
                                       GcodeOptions& options,
                                       std::optional<std::uint64_t>& generation) const;
  /// program.begin/chunk/commit into `slot` ("" main, "mdi") with the offsets' generation the
  /// blocks were made with (cycle.start refuses them once the offsets change).
  bridge::Reply upload_blocks(const std::vector<machining::MotionBlock>& blocks,
                              const std::string& slot,
                              std::optional<std::uint64_t> generation) const;
  /// Takes a committed program as the one loaded (its report starts afresh). Lock held.
  void load_locked(std::string part, std::string text, std::vector<machining::MotionBlock> blocks,
                   const std::vector<BlockFrame>& frames, const machining::Vec3& start,
                   std::uint64_t generation);

  bridge::Client& client_;
  mutable std::mutex mutex_;
  std::string machine_name_;
  machining::MachineTables tables_;
  bool have_tables_{false};
  bridge::Json machine_raw_;
  WorkOffsets offsets_;
  std::optional<std::uint64_t> offsets_generation_;  // absent: edmplc has no offset.get
  bridge::Json offsets_json_;
  std::optional<bridge::StatusMessage> last_status_;
  // The loaded program.
  std::string part_, text_;
  std::vector<machining::MotionBlock> blocks_;
  std::vector<BlockFrame> frames_;
  std::uint64_t generation_{0};
  std::optional<std::int32_t> resumed_from_;
  bridge::Json toolpath_ = bridge::Json::array();
  bridge::Json frame_runs_ = bridge::Json::array();
  bridge::Json drills_ = bridge::Json::array();
  // The job being followed and its report.
  bool started_{false};
  bool dry_run_{false};
  JobReport report_;
  bool report_done_{false};
  // Alarms that come with the end (after the last status) still belong to the report.
  std::chrono::steady_clock::time_point report_done_at_{};
};

/// The preview of a program: the tool tip's path as points (arcs and orbits as chords of at most
/// 10°), thinned to at most `max_points`.
bridge::Json toolpath_points(const std::vector<machining::MotionBlock>& blocks,
                             const machining::Vec3& start, std::size_t max_points);

}  // namespace edm::hmi
