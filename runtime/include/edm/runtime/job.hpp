#pragma once
// JobStore: the part program the runtime owns (DESIGN §2) and the real-time cursor through it.
//
// Non-RT side (the bridge's program.commit, tests): load() swaps in a whole, already checked
// program of motion blocks — only when no job is active. RT side (the job sequencer program):
// rt_begin() at cycle start, rt_current()/rt_advance() while running, rt_finish() at the end.
// Once begun, a job runs to its end from the store alone: nothing the HMI does (disconnect, kill)
// touches it; load() is refused with kBusy until the job has finished.
//
// Synchronisation: one atomic phase word. load() moves it Idle → Loading → Idle with a CAS;
// rt_begin() moves it Idle → Active with a CAS, rt_finish() Active → Idle. The RT side reads the
// program only while it holds Active, so the loader can free the old program right after its
// swap. Both sides are lock-free; the RT side never allocates or frees.
// Progress (index, count, outcome, counters) is published in atomics any thread may read.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "edm/machining/motion_block.hpp"

namespace edm::rt {

enum class JobOutcome : std::uint8_t {
  kNone = 0,      // no job has run since the last load
  kRunning = 1,   // a job is active
  kFinished = 2,  // the last job reached its end
  kAborted = 3,   // the last job was stopped (operator stop, fault, E-stop)
};

/// The outcome's name in the bridge protocol and the MQTT metrics: none, running, finished,
/// aborted.
constexpr std::string_view outcome_name(JobOutcome o) noexcept {
  switch (o) {
    case JobOutcome::kNone: return "none";
    case JobOutcome::kRunning: return "running";
    case JobOutcome::kFinished: return "finished";
    case JobOutcome::kAborted: return "aborted";
  }
  return "none";
}

enum class LoadResult : std::uint8_t { kOk, kBusy };

/// Which program a job runs: the loaded part program, or the one-line program of MDI (issue 21),
/// which never replaces the part program.
enum class JobSlot : std::uint8_t { kMain = 0, kMdi = 1 };

/// How the next job starts (set by the bridge's cycle.start before it commands kStart).
struct StartOptions {
  JobSlot slot{JobSlot::kMain};
  bool dry_run{false};  // the motion with the generator off; drill and orbit blocks skipped
};

struct JobProgress {
  JobOutcome outcome{JobOutcome::kNone};
  std::uint64_t generation{0};  // increments on every successful load()
  std::uint64_t jobs_started{0};
  std::size_t block_index{0};  // index of the block being executed (= count when finished)
  std::size_t block_count{0};  // blocks in the loaded program
  std::int32_t line{0};        // G-code line of the block being executed
  std::uint32_t program_id{
      0};  // the id the program was loaded under (bridge: its CRC-32); 0 = none
  JobSlot slot{JobSlot::kMain};  // the program the current (or last) job runs
  bool dry_run{false};           // the current (or last) job is a dry run
};

class JobStore {
 public:
  JobStore() = default;
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  /// Non-RT. Replaces the loaded program (validated by the caller). kBusy while a job is active
  /// or another load is in progress; the previous program is then kept untouched. `program_id`
  /// names it in progress() and in the retained job record (the bridge passes the CRC-32 it was
  /// committed with; 0 = unnamed).
  LoadResult load(std::vector<machining::MotionBlock> program, std::uint32_t program_id = 0);
  /// Non-RT. Replaces the MDI program (kBusy as load()); the part program is untouched.
  LoadResult load_mdi(std::vector<machining::MotionBlock> program);
  /// Number of blocks in the MDI program (0 = none).
  [[nodiscard]] std::size_t loaded_mdi_blocks() const noexcept {
    return mdi_count_.load(std::memory_order_acquire);
  }
  /// Any thread: how the next rt_begin() starts (the bridge, just before commanding kStart).
  void set_start_options(StartOptions o) noexcept {
    next_slot_.store(o.slot, std::memory_order_relaxed);
    next_dry_run_.store(o.dry_run, std::memory_order_release);
  }
  /// Any thread: the options of the current (or last) job.
  [[nodiscard]] StartOptions current_options() const noexcept {
    return {cur_slot_.load(std::memory_order_relaxed),
            cur_dry_run_.load(std::memory_order_acquire)};
  }
  /// Non-RT. Number of blocks in the loaded program (0 = none).
  [[nodiscard]] std::size_t loaded_blocks() const noexcept {
    return count_.load(std::memory_order_acquire);
  }

  /// RT-safe. Starts a job at block 0 of the program set_start_options() chose (the part program
  /// by default; the options then return to the default). False (nothing changed) when there is
  /// no such program, a job is already active, or a load is in progress.
  bool rt_begin() noexcept;
  /// RT-safe. The block being executed, or nullptr when no job is active or it is past the end.
  [[nodiscard]] const machining::MotionBlock* rt_current() const noexcept;
  /// RT-safe. Moves to the next block (index = count past the last one).
  void rt_advance() noexcept;
  /// RT-safe. Ends the active job (no-op if none) with kFinished or kAborted.
  void rt_finish(JobOutcome outcome) noexcept;
  /// Any thread.
  [[nodiscard]] bool active() const noexcept {
    return phase_.load(std::memory_order_acquire) == Phase::kActive;
  }
  /// Any thread; the fields are read one by one (each is consistent, the set nearly so).
  [[nodiscard]] JobProgress progress() const noexcept;

  /// Non-RT, at configure time: a block that runs the loaded program (EdmJob) says so; a
  /// cycle start on such a machine then needs a program (the bridge refuses it otherwise).
  void attach_runner() noexcept { runner_.store(true, std::memory_order_release); }
  /// Any thread.
  [[nodiscard]] bool has_runner() const noexcept { return runner_.load(std::memory_order_acquire); }

 private:
  enum class Phase : std::uint8_t { kIdle, kLoading, kActive };
  using Program = std::vector<machining::MotionBlock>;

  std::atomic<Phase> phase_{Phase::kIdle};
  std::unique_ptr<const Program> program_;  // written only in Loading, read only in Active
  std::unique_ptr<const Program> mdi_;      // idem
  const Program* running_{nullptr};         // program_ or mdi_: written by rt_begin (Active)
  std::atomic<std::size_t> count_{0};
  std::atomic<std::size_t> mdi_count_{0};
  std::atomic<JobSlot> next_slot_{JobSlot::kMain};
  std::atomic<bool> next_dry_run_{false};
  std::atomic<JobSlot> cur_slot_{JobSlot::kMain};
  std::atomic<bool> cur_dry_run_{false};
  std::atomic<std::size_t> index_{0};
  std::atomic<std::int32_t> line_{0};
  std::atomic<std::uint32_t> program_id_{0};
  std::atomic<JobOutcome> outcome_{JobOutcome::kNone};
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<std::uint64_t> jobs_started_{0};
  std::atomic<bool> runner_{false};
};

}  // namespace edm::rt
