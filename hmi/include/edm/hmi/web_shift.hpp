#pragma once
// The operator's long procedures of `edmhmi serve` (docs/web.md "The shift"): the job queue
// (job_queue.hpp) and the electrode measurement (electrode_measure.hpp), each on a thread and a
// bridge session of its own — they follow their jobs through events, which the hub's one session
// carries for every browser — so a queue waiting for an electrode change goes on waiting while
// the operator measures the new one.
//
//   queue.add (checked by the hub first) ─▶ items ─▶ queue.start ─▶ queue thread: run_queue()
//   electrode.measure ─▶ measure thread: measure_electrode()
//   both ─▶ state (mutex) ─▶ snapshot() / take_changes() ─▶ the hub's next frame
//
// Bounded: kMaxItems programs of at most kMaxWebProgramBytes each, kMaxJobs jobs and kMaxNotes
// notes kept (the oldest dropped). Like the job, the queue lives here, not in a browser: a page
// that reloads or closes changes nothing.
//
// Non-RT. Thread-safe: every public member locks one mutex and none blocks on the bridge (the
// threads do); the destructor interrupts both procedures and joins them.

#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/connection.hpp"
#include "edm/hmi/electrode_measure.hpp"
#include "edm/hmi/job_queue.hpp"

namespace edm::hmi {

class WebShift {
 public:
  static constexpr std::size_t kMaxItems = 20;
  static constexpr int kMaxRepeat = 100;
  static constexpr double kMaxStepMm = 1000.0;
  static constexpr std::size_t kMaxJobs = 200;
  static constexpr std::size_t kMaxNotes = 20;

  explicit WebShift(ConnectionSettings settings) : settings_(std::move(settings)) {}
  ~WebShift();
  WebShift(const WebShift&) = delete;
  WebShift& operator=(const WebShift&) = delete;

  /// Appends a program (already checked). Refused while the queue runs, and for a repeat
  /// outside 1..kMaxRepeat or a step over kMaxStepMm.
  bridge::Json add(const QueueItem& item);
  /// "clear" (not while running), "start" (not empty, not running), "stop" (the current job is
  /// stopped as the operator's stop, and the queue ends).
  bridge::Json control(std::string_view action);
  /// Starts a measurement on "setter" or "work" (`frame`: the surface's frame, "" the active).
  bridge::Json measure(const std::string& reference, const std::string& frame);
  /// Interrupts both procedures and joins them. Idempotent.
  void stop_all();

  /// {"items":[{"name","repeat","step_x","step_y","bytes"}],"running","waiting_change","ok","message","current",
  ///  "jobs":[…],"notes":[…],"measure":{…},"generation"}.
  [[nodiscard]] bridge::Json snapshot() const;
  /// The snapshot when it changed since the last call, else null.
  [[nodiscard]] bridge::Json take_changes();

 private:
  struct Hole {
    std::int32_t line{0};
    double target_mm{0.0};  // the drilling block's depth below the surface
    double depth_mm{-1.0};  // io.depth_mm, the simulator's hole, deepest seen (-1: not published)
  };
  struct Job {
    std::string part;
    int run{1};
    int from_line{0};
    int before_line{0};
    std::string outcome;
    std::string message;
    std::vector<Hole> holes;
    double time_s{0.0};
    std::vector<std::string> alarms;
  };
  void run_queue_thread(std::vector<QueueItem> items);
  void run_measure_thread(MeasureRequest request);
  void on_progress(const ProgressView& v);
  void note_locked(std::string text);
  [[nodiscard]] bridge::Json snapshot_locked() const;
  void changed_locked() { ++generation_; }

  ConnectionSettings settings_;
  std::atomic<bool> queue_interrupt_{false};
  std::atomic<bool> measure_interrupt_{false};
  std::thread queue_thread_;
  std::thread measure_thread_;

  mutable std::mutex mutex_;
  std::vector<QueueItem> items_;
  bool running_{false};
  bool waiting_change_{false};
  bridge::Json ok_;  // null until a queue ended, then true/false
  std::string message_;
  Job current_;  // the job running (part empty: none)
  std::deque<Job> jobs_;
  std::deque<std::string> notes_;
  bridge::Json measure_ = bridge::Json::object();
  bool measuring_{false};
  std::uint64_t generation_{0};
  std::uint64_t sent_generation_{0};
};

}  // namespace edm::hmi
