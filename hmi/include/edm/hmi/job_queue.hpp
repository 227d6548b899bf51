#pragma once
// The job queue of edmhmi `queue` (docs/hmi.md "A job queue"): several part programs, or one
// repeated, run one after the other without an operator between them. Each job is interpreted
// just before it starts, with the machine's work frames and position then, and run with
// run_job() (job_runner.hpp); the runtime logs each one (jobs.get).
//
// The electrode. Before each job the queue plans its wear hole by hole (eq. 9-11,
// machining::planned_wear) against the electrode left (electrode.get: usable_mm, the length less
// the supervisor's margin). When a hole would not be finished:
//   - the holes before it run (the program up to that hole's block, then a rapid straight up to
//     1 mm below the top of Z, its soft limit, so that a longer new electrode fits in, then an
//     end);
//   - the machine stops there and the queue asks for an electrode change (callbacks.note) and
//     waits — for as long as it takes, or the interrupt — until the electrode in the spindle is
//     another one or another length, and measured (electrode.change, electrode.measure);
//   - the program then goes on from that hole (plan_resume), interpreted again.
// A job that ends aborted (a stop, a fault, an E-stop) stops the queue: the operator looks first.
//
// Non-RT. Not thread-safe: one queue at a time per Client; `interrupt` may be set from a signal
// handler (it is only read).

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/job_runner.hpp"

namespace edm::hmi {

struct QueueItem {
  std::string part;  // its name in messages and reports
  std::string text;  // the G-code
  int repeat{1};     // runs of it, >= 1
  /// Run k (from 1) is interpreted with every work frame moved by (k − 1) × this in X and Y: a
  /// row of holes or of parts, each run on fresh material (mm; 0: every run at the same place).
  double step_x_mm{0.0};
  double step_y_mm{0.0};
};

/// One job the queue ran (a program split by an electrode change is two jobs).
struct QueueJob {
  std::string part;
  int run{1};          // which repetition of its item, from 1
  int from_line{0};    // > 0: it went on from this line after an electrode change
  int before_line{0};  // > 0: it stopped before this line's hole for an electrode change
  RunResult result;
};

struct QueueCallbacks {
  RunCallbacks run;                                // passed to each job
  std::function<void(const QueueJob&)> job_start;  // before each job (result not yet set)
  std::function<void(const QueueJob&)> job_done;   // after each job
  std::function<void(const std::string&)> note;    // an electrode change is needed, …
  std::function<void(bool)> waiting;               // true: waiting for a change; false: it came
  std::chrono::milliseconds electrode_poll{500};   // electrode.get while waiting for a change
};

struct QueueResult {
  bool ok{false};       // every job of every item finished
  std::string message;  // why not
  std::vector<QueueJob> jobs;
};

QueueResult run_queue(bridge::Client& client, const std::vector<QueueItem>& items,
                      const QueueCallbacks& callbacks, const std::atomic<bool>& interrupt);

}  // namespace edm::hmi
