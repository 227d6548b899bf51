#pragma once
// The job that `edmhmi serve` owns on behalf of every browser (docs/web.md): the part program
// text, its interpretation against the machine's own tables (machine.info), the upload, the
// start, and the job report built from the runtime's figures when the job ends.
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
  /// {"name", "axes", "conditions"} as machine.info gave them (null before refresh_machine()).
  [[nodiscard]] bridge::Json machine_info() const;

  /// Interprets `text` against the machine's tables from the current position, nothing sent.
  /// {"ok", "errors": [{"line","col","message"}], "blocks", "drill_blocks", "drill_depth_mm",
  ///  "electrode_wear_mm"}.
  bridge::Json check(const std::string& text, const std::string& name);
  /// check(), then program.begin/chunk/commit. {"ok", ...} or {"ok": false, "code", "message",
  /// "errors"} (interpreter errors or the commit's issues, located at their lines).
  bridge::Json upload(const std::string& text, const std::string& name);
  /// cycle.start of the committed program (electrode length noted for the report).
  bridge::Reply start();

  /// Status and alarm events of the server's own bridge session.
  void on_status(const bridge::StatusMessage& s);
  void on_alarm(const bridge::Json& alarm_event);

  /// What a browser needs to show the job: {"part", "text", "generation", "blocks",
  /// "toolpath": [[x,y,z],…], "report": null | {"text", "outcome", …}}.
  [[nodiscard]] bridge::Json snapshot() const;

 private:
  std::optional<machining::Vec3> position_locked() const;
  /// The G-code interpreted against a copy of the tables from the current position (returned in
  /// options.start_mm), outside the lock; nullopt before refresh_machine().
  std::optional<GcodeResult> interpret(const std::string& text, const std::string& name,
                                       GcodeOptions& options) const;

  bridge::Client& client_;
  mutable std::mutex mutex_;
  std::string machine_name_;
  machining::MachineTables tables_;
  bool have_tables_{false};
  std::optional<bridge::StatusMessage> last_status_;
  // The loaded program.
  std::string part_, text_;
  std::vector<machining::MotionBlock> blocks_;
  std::uint64_t generation_{0};
  bridge::Json toolpath_ = bridge::Json::array();
  // The job being followed and its report.
  bool started_{false};
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
