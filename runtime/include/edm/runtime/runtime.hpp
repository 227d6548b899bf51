#pragma once
// The runtime: everything a config describes, built and wired — the I/O driver, the programs
// and their blocks, the tasks, the variable registry, the trace recorder and the retain store —
// and run on the real or the virtual clock.
//
// Thread-safety: build and run from one controlling thread. While running, machine(),
// variables() and stats are safe to use from other non-RT threads.

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/electrode.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/job.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/manual.hpp"
#include "edm/runtime/program.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/stats_json.hpp"
#include "edm/runtime/supervisor.hpp"
#include "edm/runtime/task.hpp"
#include "edm/runtime/trace.hpp"
#include "edm/runtime/type_registry.hpp"
#include "edm/runtime/variables.hpp"
#include "edm/runtime/work_offsets.hpp"

namespace edm::rt {

struct BuildOptions {
  std::optional<std::uint64_t> seed;  // overrides the driver's seed (--seed)
  /// Read the retain file at build and keep the store that writes it. false (--check,
  /// --list-vars, offline tools): no store is constructed, so nothing can write the file.
  bool load_retain{true};
  /// The state directory: a relative `retain.file` is resolved against it (edmplc: --state-dir,
  /// else $EDM_STATE_DIR). Empty: a relative retain file is not used (no store, an info line),
  /// so a library user or a test that runs a shipped config never reads nor writes one by
  /// accident. An absolute `retain.file` is used as written either way.
  std::string state_dir;
};

/// The job the retain file showed running when the previous runtime stopped without a clean
/// shutdown (kill -9, power loss). The seam for resuming it from its block (issue 21).
struct InterruptedJob {
  std::uint32_t program_id{0};       // the id it was committed under (bridge: CRC-32); 0 = none
  std::int64_t block_index{0};       // the block being executed (0-based)
  std::int64_t block_count{0};       // blocks in the program
  std::int64_t line{0};              // its G-code line
  std::optional<double> depth_mm;    // `retain.job_depth` at the last retain write, if configured
  std::optional<double> touch_z_mm;  // `retain.job_touch_z`: the drill's depth origin (machine Z)
  std::optional<double> wear_mm;     // `retain.job_wear`: the wear it had compensated since
};

struct RunOptions {
  ClockKind clock{ClockKind::kReal};
  std::optional<Duration> run_for;         // nullopt: until *stop
  const std::atomic<bool>* stop{nullptr};  // set by a signal handler
  std::string trace_out;                   // CSV path; empty: no trace file
  /// Virtual clock only: > 0 paces virtual time to `speed` × wall time (an accelerated but
  /// still deterministic machine, e.g. for an HMI to follow a job); 0 runs as fast as possible.
  double speed{0.0};
};

struct RunSummary {
  MachineState final_state{MachineState::kOff};
  bool fifo_degraded{false};
  std::uint64_t trace_dropped{0};
  std::uint64_t alarms_dropped{0};
};

class Runtime {
 public:
  /// Builds everything the config describes. Throws ConfigError (every problem, file:line:col).
  static std::unique_ptr<Runtime> build(const Config& cfg, const BlockRegistry& blocks,
                                        const DriverRegistry& drivers,
                                        const BuildOptions& options = {});
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  /// Powers on (READY), runs the tasks until run_for elapses or *stop, then stops in order:
  /// safe state, tasks joined, retain flushed, trace written. Throws std::runtime_error on a
  /// start-up failure (threads, CPU, trace file).
  RunSummary run(const RunOptions& options);

  [[nodiscard]] Machine& machine() noexcept { return machine_; }
  [[nodiscard]] VariableRegistry& variables() noexcept { return variables_; }
  [[nodiscard]] IoDriver& driver() noexcept { return *driver_; }
  /// The I/O driver exchanges with real devices in wall time (IoDriver::wall_time_io()).
  [[nodiscard]] bool wall_time_io() const noexcept { return driver_ && driver_->wall_time_io(); }
  [[nodiscard]] const std::vector<std::unique_ptr<Task>>& tasks() const noexcept { return tasks_; }
  [[nodiscard]] Program* program(std::string_view name) const;
  [[nodiscard]] TraceRecorder& trace() noexcept { return trace_; }
  [[nodiscard]] RetainStore* retain() noexcept { return retain_.get(); }
  /// Why the retained values are defaults (a corrupt file was set aside), or "".
  [[nodiscard]] const std::string& retain_warning() const noexcept { return retain_warning_; }
  /// The job an unclean stop interrupted (alarm 182 at power-on), or nullopt. Fixed for the life
  /// of this runtime; the retain file keeps the record until the next job begins. Any thread.
  [[nodiscard]] const std::optional<InterruptedJob>& interrupted_job() const noexcept {
    return interrupted_job_;
  }
  /// The resolved retain file (`retain.file` against BuildOptions::state_dir), or "" when no
  /// retain store is in use.
  [[nodiscard]] const std::string& retain_path() const noexcept { return retain_path_; }
  [[nodiscard]] std::vector<TaskStatsReport> stats_reports() const;
  [[nodiscard]] const Config& config() const noexcept { return config_; }
  /// The loaded part program and its progress (DESIGN §2: the runtime owns it).
  [[nodiscard]] JobStore& job() noexcept { return job_; }
  /// The operator's manual motion (reference, jog, touch-off): requests in, state out.
  [[nodiscard]] ManualControl& manual() noexcept { return manual_; }
  /// The work offsets G54…G59 (retained with the job record when there is a retain file).
  [[nodiscard]] WorkOffsets& work_offsets() noexcept { return work_offsets_; }
  /// The electrode length estimate (electrode.hpp; `machine.electrode` gives the first one,
  /// retained like the work offsets).
  [[nodiscard]] Electrode& electrode() noexcept { return electrode_; }
  /// The safety supervisor of `machine.safety`, or nullptr when the config has none.
  [[nodiscard]] const Supervisor* supervisor() const noexcept { return supervisor_.get(); }
  /// Adds a consumer of every alarm (besides the log): called on the controlling thread, in
  /// order, each time run() drains the machine's alarm queue (every ~20 ms on the real clock,
  /// every 1024 cycles on the virtual one). The RT side only ever pushes into that lock-free
  /// queue, so a slow listener delays the log, never a task. Non-RT; call before run().
  void add_alarm_listener(std::function<void(const Alarm&)> listener) {
    alarm_listeners_.push_back(std::move(listener));
  }
  /// The config's conditions and soft limits, in the form part programs are checked against.
  [[nodiscard]] const machining::MachineTables& tables() const noexcept { return tables_; }
  /// Sets one field of condition E `e` (an operator's edit, condition.set): only a field the
  /// config lists in machine.condition_edit, within the config's own range. nullopt when set,
  /// else why not. Non-RT, and only while no job runs (the caller's op state: READY idle): a job
  /// reads its conditions as its blocks begin, and its start (a command through the machine's
  /// lock-free queue) orders this write before those reads.
  std::optional<std::string> set_condition_field(int e, std::string_view field, double value);

 private:
  friend class RuntimeBuilder;
  friend class RetainBuilder;
  Runtime() = default;
  void drain_alarms();

  Config config_;
  machining::MachineTables tables_;
  Machine machine_;
  JobStore job_;
  ManualControl manual_;
  WorkOffsets work_offsets_;
  Electrode electrode_;
  std::unique_ptr<IoDriver> driver_;
  std::unique_ptr<Supervisor> supervisor_;  // after driver_: it points into the driver's pins
  std::vector<std::unique_ptr<Program>> programs_;
  std::vector<std::unique_ptr<Task>> tasks_;
  VariableRegistry variables_;
  TraceRecorder trace_;
  bool has_trace_{false};
  std::unique_ptr<RetainStore> retain_;
  std::string retain_warning_;
  AlarmCode startup_alarm_{AlarmCode::kNone};  // raised at power-on in run() (retain lost)
  std::optional<InterruptedJob> interrupted_job_;
  std::string job_alarm_text_;  // alarm 182's text (the alarm holds a pointer to it)
  bool job_alarm_raised_{false};
  std::string retain_path_;
  bool ran_{false};  // only a runtime that ran flushes the retain file when destroyed
  std::vector<std::function<void(const Alarm&)>> alarm_listeners_;
};

}  // namespace edm::rt
