#pragma once
// Per-task statistics as CODESYS's task monitor shows them: cycle count, execution time and
// release latency (actual start - scheduled release) min/avg/p50/p99/max, overruns, omitted cycles.
//
// Thread safety: one writer (the task's RT thread: record_cycle(), record_overrun()) and any
// number of concurrent readers (snapshot()). reset() only while the task is not running.
// RT safety: record_cycle() and record_overrun() are RT-safe (noexcept, O(1), no allocation, no
// locks, never wait for readers). snapshot() is not RT (scans the histograms; may retry).

#include <cstdint>

#include "edm/runtime/histogram.hpp"
#include "edm/runtime/seqlock.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

/// Microseconds. All 0 when no cycle was recorded.
struct DurationSummary {
  double min_us{0.0};
  double avg_us{0.0};
  double p50_us{0.0};
  double p99_us{0.0};
  double max_us{0.0};
};

struct TaskStatsSnapshot {
  std::uint64_t cycles{0};
  std::uint64_t overruns{0};
  std::uint64_t omitted_cycles{0};
  DurationSummary exec;
  DurationSummary latency;
};

/// Counters and min/max/sum are published through a Seqlock (seqlock.hpp), so a snapshot is never
/// torn; p50/p99 come from two LatencyHistograms read after the scalars, so they may include a few
/// cycles newer than `cycles` (they are clamped into the snapshot's [min, max]).
/// Not copyable or movable (atomics; about 37 KiB, no heap).
class TaskStats {
 public:
  TaskStats() = default;
  TaskStats(const TaskStats&) = delete;
  TaskStats& operator=(const TaskStats&) = delete;

  /// Records one executed cycle: its release latency and execution time (ns resolution).
  /// @note RT-safe; single writer only.
  void record_cycle(Duration latency, Duration exec) noexcept;

  /// Records one overrun that made the task skip `omitted_cycles` releases (0 for policy asap).
  /// @note RT-safe; single writer only.
  void record_overrun(std::uint64_t omitted_cycles) noexcept;

  /// A consistent copy of the statistics. Never blocks the writer; retries while it writes.
  /// @note Any thread, concurrently with the writer. Not RT.
  [[nodiscard]] TaskStatsSnapshot snapshot() const;

  /// Clears everything. @note Not thread-safe: only while the task is not running and nobody
  /// takes a snapshot.
  void reset() noexcept;

 private:
  /// Scalars of one measured quantity (ns).
  struct Extremes {
    std::int64_t min_ns{0};  // valid only when cycles > 0
    std::int64_t max_ns{0};
    std::int64_t sum_ns{0};
  };
  /// Everything but the histograms, published as one value.
  struct Scalars {
    std::uint64_t cycles{0};
    std::uint64_t overruns{0};
    std::uint64_t omitted_cycles{0};
    Extremes exec;
    Extremes latency;
  };

  Scalars own_;                 // the writer's working copy, read and written by the writer only
  Seqlock<Scalars> published_;  // what snapshot() reads
  LatencyHistogram exec_histogram_;
  LatencyHistogram latency_histogram_;
};

}  // namespace edm::rt
