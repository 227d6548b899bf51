#pragma once
// The job runner of edmhmi `run` (docs/hmi.md): asks edmplc for its machine tables, uploads the
// interpreted program, starts the cycle and follows the job to its end through status, progress
// and alarm events, then builds the job report from the runtime's own figures.
//
// The runtime owns the job once committed: losing the connection, or this process dying, does not
// stop it (the client reconnects by itself; `edmhmi status` shows the outcome later). An
// interrupt (Ctrl-C) asks the machine to stop — the operator's stop, not an abandonment.
//
// Non-RT. Not thread-safe: one run at a time per Client; `interrupt` may be set from a signal
// handler (it is only read).

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/job_report.hpp"
#include "edm/hmi/work_offsets.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::hmi {

/// What the machine says about itself before a program is interpreted for it.
struct MachineView {
  std::string name;
  machining::MachineTables tables;
  machining::Vec3 position{};  // io.x_mm / io.y_mm / io.z_mm of the status (0 when absent)
  bridge::StatusMessage status;
  std::optional<bridge::LastJob> last_job;  // status job.last: a job that may be resumed
  WorkOffsets offsets;                      // offset.get (zero when the runtime has no such op)
  std::optional<std::uint64_t> offsets_generation;  // offset.get's generation (absent: no op)
  std::optional<double> deadman_ms;                 // machine.info "manual": {"deadman_ms"}
};

/// machine.info + status + offset.get. Throws bridge::ClientError when one is refused or
/// malformed (an older runtime's unknown_op for offset.get leaves the offsets zero).
MachineView fetch_machine(bridge::Client& client);

/// offset.get: the frames and their generation. Throws bridge::ClientError when refused or
/// malformed.
WorkOffsets fetch_offsets(bridge::Client& client, std::uint64_t* generation = nullptr);

struct RunRequest {
  std::string part;  // the part program's name (messages and report)
  std::string machine;
  std::vector<machining::MotionBlock> blocks;
  std::vector<BlockFrame> frames;  // the work frame of each block (for the report), or empty
  std::string slot;                // program slot: "" (main, the default) or "mdi"
  std::optional<std::uint64_t> offsets_generation;  // the offsets the blocks were made with
  bool dry_run{false};  // cycle.start {"dry_run": true}: generator off, no drilling
  bool detach{false};   // return once the cycle has started
  int rate_hz{10};      // status events while following the job
  std::chrono::milliseconds lost_limit{std::chrono::seconds(60)};  // give up after this offline
};

enum class RunOutcome {
  kFinished,     // the job ran to its end block
  kAborted,      // stop, fault or E-stop ended it early
  kRefused,      // not started: busy machine, safe state, program refused at commit
  kDetached,     // started; not followed (RunRequest::detach)
  kLost,         // the connection stayed down past lost_limit; the job may still run
  kInterrupted,  // stopped by the operator's interrupt
};

struct RunResult {
  RunOutcome outcome{RunOutcome::kRefused};
  std::string message;                 // why, for kRefused / kLost
  std::vector<std::string> locations;  // commit issues as "part:line:col: message"
  bool bad_program{false};             // refused because of the program (exit 2)
  JobReport report;
};

struct RunCallbacks {
  std::function<void(const ProgressView&)> progress;  // on each status event (main thread)
  std::function<void(const std::string&)> alarm;      // each alarm as it comes (main thread)
  std::function<void(const std::string&)> note;       // connection lost / back, stop sent, ...
};

RunResult run_job(bridge::Client& client, const RunRequest& request, const RunCallbacks& callbacks,
                  const std::atomic<bool>& interrupt);

/// One alarm event as "141 soft_limit (fault, cnc.job): text".
std::string describe_alarm(const bridge::Json& event);

}  // namespace edm::hmi
