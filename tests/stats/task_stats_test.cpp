#include "edm/runtime/task_stats.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <thread>

namespace edm::rt {
namespace {

using std::chrono::microseconds;

// ~37 KiB: keep it off the test thread's stack.
std::unique_ptr<TaskStats> make_stats() { return std::make_unique<TaskStats>(); }

TEST(TaskStats, empty_snapshot_is_all_zero) {
  auto stats = make_stats();
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_EQ(s.cycles, 0u);
  EXPECT_EQ(s.overruns, 0u);
  EXPECT_EQ(s.omitted_cycles, 0u);
  for (const DurationSummary& d : {s.exec, s.latency}) {
    EXPECT_EQ(d.min_us, 0.0);
    EXPECT_EQ(d.avg_us, 0.0);
    EXPECT_EQ(d.p50_us, 0.0);
    EXPECT_EQ(d.p99_us, 0.0);
    EXPECT_EQ(d.max_us, 0.0);
  }
}

TEST(TaskStats, min_avg_max_are_exact) {
  auto stats = make_stats();
  stats->record_cycle(microseconds(3), microseconds(40));
  stats->record_cycle(microseconds(1), microseconds(10));
  stats->record_cycle(microseconds(4), microseconds(30));
  stats->record_cycle(microseconds(2), Duration(20'001));
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_EQ(s.cycles, 4u);
  EXPECT_DOUBLE_EQ(s.exec.min_us, 10.0);
  EXPECT_DOUBLE_EQ(s.exec.max_us, 40.0);
  EXPECT_DOUBLE_EQ(s.exec.avg_us, 25.00025);
  EXPECT_DOUBLE_EQ(s.latency.min_us, 1.0);
  EXPECT_DOUBLE_EQ(s.latency.max_us, 4.0);
  EXPECT_DOUBLE_EQ(s.latency.avg_us, 2.5);
  // p50 = 2nd smallest of 4, reported as its bucket's upper bound (<= 1/64 above).
  EXPECT_GE(s.exec.p50_us, 20.001);
  EXPECT_LE(s.exec.p50_us, 20.001 * (1.0 + 1.0 / 64));
  EXPECT_DOUBLE_EQ(s.exec.p99_us, 40.0);  // capped at the exact max
}

TEST(TaskStats, p99_ignores_one_percent_of_outliers) {
  auto stats = make_stats();
  for (int i = 0; i < 1000; ++i) {
    const bool outlier = i % 100 == 37;  // 10 of 1000
    stats->record_cycle(microseconds(5), outlier ? microseconds(5000) : microseconds(100));
  }
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_GE(s.exec.p99_us, 100.0);
  EXPECT_LE(s.exec.p99_us, 100.0 * (1.0 + 1.0 / 64));
  EXPECT_DOUBLE_EQ(s.exec.max_us, 5000.0);
  EXPECT_DOUBLE_EQ(s.exec.avg_us, (990 * 100.0 + 10 * 5000.0) / 1000);

  // One more outlier pushes it above 1 %: now p99 is the outlier.
  for (int i = 0; i < 2; ++i) {
    stats->record_cycle(microseconds(5), microseconds(5000));
  }
  EXPECT_DOUBLE_EQ(stats->snapshot().exec.p99_us, 5000.0);
}

TEST(TaskStats, counts_overruns_and_omitted_cycles) {
  auto stats = make_stats();
  stats->record_overrun(0);
  stats->record_overrun(3);
  stats->record_cycle(microseconds(1), microseconds(1));
  stats->record_overrun(2);
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_EQ(s.overruns, 3u);
  EXPECT_EQ(s.omitted_cycles, 5u);
  EXPECT_EQ(s.cycles, 1u);
}

TEST(TaskStats, negative_latency_keeps_exact_extremes) {
  auto stats = make_stats();
  stats->record_cycle(microseconds(-5), microseconds(10));
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_DOUBLE_EQ(s.latency.min_us, -5.0);
  EXPECT_DOUBLE_EQ(s.latency.max_us, -5.0);
  // The histogram saw 0 (it clamps); the percentiles are clamped into [min, max].
  EXPECT_DOUBLE_EQ(s.latency.p50_us, -5.0);
}

TEST(TaskStats, reset_starts_over) {
  auto stats = make_stats();
  stats->record_cycle(microseconds(1), microseconds(1));
  stats->record_overrun(4);
  stats->reset();
  EXPECT_EQ(stats->snapshot().cycles, 0u);
  EXPECT_EQ(stats->snapshot().overruns, 0u);
  EXPECT_EQ(stats->snapshot().exec.max_us, 0.0);
  stats->record_cycle(microseconds(7), microseconds(9));
  const TaskStatsSnapshot s = stats->snapshot();
  EXPECT_DOUBLE_EQ(s.exec.min_us, 9.0);  // not min(0, 9): the first cycle sets min
  EXPECT_DOUBLE_EQ(s.latency.p99_us, 7.0);
  EXPECT_EQ(s.omitted_cycles, 0u);
}

// Cycle i (1-based) records exec = i ns and latency = kSum - i ns, and every 16th cycle is
// followed by an overrun omitting 2. In any consistent state with c cycles: exec max = c,
// latency min = kSum - c, avg exec + avg latency = kSum, avg exec = (c + 1) / 2,
// omitted = 2 * overruns, and overruns is c / 16 or (just before the overrun) one less.
// A snapshot mixing two writes breaks at least one of these.
TEST(TaskStats, concurrent_snapshots_are_never_torn) {
  constexpr std::int64_t kSum = std::int64_t{1} << 30;
  constexpr int kMinSnapshots = 5000;
  constexpr int kMinOverlaps = 2000;
  auto stats = make_stats();
  std::atomic<bool> writer_started{false};
  std::atomic<bool> reader_done{false};
  std::atomic<std::int64_t> written{0};

  std::thread writer([&] {
    std::int64_t i = 0;
    // Runs until the reader is done so that every snapshot overlaps writes.
    while (!reader_done.load(std::memory_order_acquire) && i < kSum - 1) {
      ++i;
      stats->record_cycle(Duration(kSum - i), Duration(i));
      if (i % 16 == 0) {
        stats->record_overrun(2);
      }
      if (i == 1) {
        writer_started.store(true, std::memory_order_release);
      }
    }
    written.store(i, std::memory_order_relaxed);
  });

  while (!writer_started.load(std::memory_order_acquire)) {
    std::this_thread::yield();
  }
  int failures = 0;
  int progressions = 0;
  std::uint64_t last_cycles = 0;
  // Tearing needs the threads to run at the same time, which a loaded machine rarely grants:
  // keep going until enough snapshots overlapped writes, bounded by wall time (not a sleep).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  int snapshots = 0;
  while (failures < 10 &&
         (snapshots < kMinSnapshots ||
          (progressions < kMinOverlaps && std::chrono::steady_clock::now() < give_up))) {
    ++snapshots;
    const TaskStatsSnapshot s = stats->snapshot();
    const auto c = static_cast<std::int64_t>(s.cycles);
    const auto ns = [](double us) { return std::llround(us * 1e3); };
    const bool ok =
        c >= 1 && ns(s.exec.max_us) == c && ns(s.exec.min_us) == 1 &&
        ns(s.latency.max_us) == kSum - 1 && ns(s.latency.min_us) == kSum - c &&
        std::abs(s.exec.avg_us - static_cast<double>(c + 1) / 2e3) < 1e-6 &&
        std::abs(s.exec.avg_us + s.latency.avg_us - static_cast<double>(kSum) / 1e3) < 1e-6 &&
        s.omitted_cycles == 2 * s.overruns &&
        (static_cast<std::int64_t>(s.overruns) == c / 16 ||
         (c % 16 == 0 && static_cast<std::int64_t>(s.overruns) == c / 16 - 1)) &&
        s.exec.p50_us >= s.exec.min_us && s.exec.p99_us <= s.exec.max_us && s.cycles >= last_cycles;
    if (!ok) {
      ++failures;
      ADD_FAILURE() << "torn snapshot: cycles=" << s.cycles << " exec max_us=" << s.exec.max_us
                    << " min_us=" << s.exec.min_us << " avg_us=" << s.exec.avg_us
                    << " latency min_us=" << s.latency.min_us << " avg_us=" << s.latency.avg_us
                    << " overruns=" << s.overruns << " omitted=" << s.omitted_cycles;
    }
    progressions += s.cycles > last_cycles ? 1 : 0;
    last_cycles = s.cycles;
  }
  reader_done.store(true, std::memory_order_release);
  writer.join();

  EXPECT_EQ(failures, 0);
  // The reader really raced the writer (otherwise the test proves nothing).
  EXPECT_GT(progressions, 1) << snapshots << " snapshots";
  EXPECT_EQ(stats->snapshot().cycles, static_cast<std::uint64_t>(written.load()));
}

}  // namespace
}  // namespace edm::rt
