#include "edm/runtime/log.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace edm::rt {
namespace {

RtLogRecord record(RtLogLevel level, const char* source, const char* fmt, double a = 0,
                   double b = 0) {
  return RtLogRecord{level, TimePoint{0}, source, fmt, {a, b, 0, 0}};
}

std::vector<RtLogRecord> drain_all(RtLogQueue& q) {
  std::vector<RtLogRecord> out;
  q.drain([&out](const RtLogRecord& r) { out.push_back(r); });
  return out;
}

TEST(RtLogQueue, drains_records_in_order_with_formatted_text) {
  RtLogQueue q;
  EXPECT_TRUE(q.push(record(RtLogLevel::kInfo, "gap", "td {:.2f} us", 12.345)));
  EXPECT_TRUE(q.push(record(RtLogLevel::kWarn, "servo", "axis {} error {} mm", 2, -0.5)));
  EXPECT_TRUE(q.push(record(RtLogLevel::kError, nullptr, "no args")));

  const auto recs = drain_all(q);
  ASSERT_EQ(recs.size(), 3u);
  EXPECT_EQ(recs[0].level, RtLogLevel::kInfo);
  EXPECT_STREQ(recs[0].source, "gap");
  EXPECT_EQ(format_rt_log_message(recs[0]), "td 12.35 us");
  EXPECT_EQ(recs[1].level, RtLogLevel::kWarn);
  EXPECT_EQ(format_rt_log_message(recs[1]), "axis 2 error -0.5 mm");
  EXPECT_EQ(format_rt_log_message(recs[2]), "no args");
  EXPECT_EQ(q.dropped(), 0u);
  EXPECT_EQ(drain_all(q).size(), 0u);
}

TEST(RtLogQueue, full_queue_counts_drops_and_never_blocks) {
  RtLogQueue q;
  constexpr std::size_t kExtra = 7;
  std::size_t accepted = 0;
  for (std::size_t i = 0; i < RtLogQueue::kCapacity + kExtra; ++i) {
    accepted += q.push(record(RtLogLevel::kInfo, "t", "{}", static_cast<double>(i))) ? 1 : 0;
  }
  EXPECT_EQ(accepted, RtLogQueue::kCapacity);
  EXPECT_EQ(q.dropped(), kExtra);

  const auto recs = drain_all(q);
  ASSERT_EQ(recs.size(), RtLogQueue::kCapacity);
  EXPECT_EQ(recs.front().args[0], 0.0);  // the oldest are kept, the newest dropped
  EXPECT_EQ(recs.back().args[0], static_cast<double>(RtLogQueue::kCapacity - 1));
  EXPECT_TRUE(q.push(record(RtLogLevel::kInfo, "t", "room again")));
  EXPECT_EQ(q.dropped(), kExtra);
}

TEST(RtLogQueue, drain_is_bounded_per_call) {
  RtLogQueue q;
  for (int i = 0; i < 10; ++i) {
    q.push(record(RtLogLevel::kInfo, "t", "{}", i));
  }
  std::size_t seen = 0;
  EXPECT_EQ(q.drain([&](const RtLogRecord&) { ++seen; }, 4), 4u);
  EXPECT_EQ(seen, 4u);
  EXPECT_EQ(q.drain([&](const RtLogRecord&) { ++seen; }), 6u);
}

TEST(RtLogQueue, concurrent_producers_lose_nothing_within_capacity) {
  RtLogQueue q;
  constexpr int kThreads = 4;
  constexpr int kPerThread = 250;  // 1000 <= kCapacity
  static_assert(kThreads * kPerThread <= static_cast<int>(RtLogQueue::kCapacity));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&q, t] {
      for (int i = 0; i < kPerThread; ++i) {
        q.push(record(RtLogLevel::kInfo, "worker", "{} {}", t, i));
      }
    });
  }
  for (auto& th : threads) {
    th.join();
  }
  const auto recs = drain_all(q);
  EXPECT_EQ(q.dropped(), 0u);
  ASSERT_EQ(recs.size(), static_cast<std::size_t>(kThreads * kPerThread));
  std::vector<int> next(kThreads, 0);
  std::set<std::pair<int, int>> seen;
  for (const auto& r : recs) {
    const int t = static_cast<int>(r.args[0]);
    const int i = static_cast<int>(r.args[1]);
    ASSERT_GE(t, 0);
    ASSERT_LT(t, kThreads);
    EXPECT_EQ(i, next[static_cast<std::size_t>(t)]) << "per-producer order broken";
    next[static_cast<std::size_t>(t)] = i + 1;
    seen.emplace(t, i);
  }
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(kThreads * kPerThread));
}

TEST(RtLogQueue, concurrent_producers_and_consumer_account_for_every_record) {
  RtLogQueue q;
  constexpr int kThreads = 4;
  constexpr int kPerThread = 5000;  // far beyond the capacity: some records must be dropped
  std::atomic<int> running{kThreads};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&q, &running, t] {
      for (int i = 0; i < kPerThread; ++i) {
        q.push(record(RtLogLevel::kInfo, "worker", "{} {}", t, i));
      }
      running.fetch_sub(1);
    });
  }
  std::vector<int> last(kThreads, -1);
  std::size_t received = 0;
  const auto take = [&](const RtLogRecord& r) {
    const auto t = static_cast<std::size_t>(r.args[0]);
    const int i = static_cast<int>(r.args[1]);
    EXPECT_GT(i, last[t]) << "per-producer order broken";
    last[t] = i;
    ++received;
  };
  while (running.load() > 0) {
    q.drain(take);
  }
  for (auto& th : threads) {
    th.join();
  }
  q.drain(take);
  EXPECT_EQ(received + q.dropped(), static_cast<std::size_t>(kThreads * kPerThread));
}

TEST(RtLogFormat, bad_format_string_returns_the_raw_format_instead_of_throwing) {
  for (const char* bad : {"value {:d}", "unclosed {", "index {7}", "{:q}"}) {
    std::string text;
    EXPECT_NO_THROW(text = format_rt_log_message(record(RtLogLevel::kWarn, "t", bad, 1.5)));
    EXPECT_NE(text.find(bad), std::string::npos) << text;
    EXPECT_NE(text.find("bad format"), std::string::npos) << text;
  }
  EXPECT_EQ(format_rt_log_message(record(RtLogLevel::kWarn, "t", nullptr)), "");
}

TEST(RtLog, global_queue_filters_by_level_and_drains_synchronously) {
  std::vector<std::string> lines;
  drain_rt_log_for_test(lines);  // start from an empty queue
  lines.clear();

  const std::uint64_t dropped_before = rt_log_dropped();
  rt_log(RtLogLevel::kDebug, "task.fast", "below the default info level {}", 1);
  rt_log(RtLogLevel::kWarn, "task.fast", "overrun by {:.1f} us", 37.26);
  rt_log(RtLogLevel::kError, "task.slow", "watchdog {} of {}", 3, 4);
  EXPECT_EQ(drain_rt_log_for_test(lines), 2u);
  EXPECT_EQ(lines, (std::vector<std::string>{"warning [task.fast] overrun by 37.3 us",
                                             "error [task.slow] watchdog 3 of 4"}));
  EXPECT_EQ(rt_log_dropped(), dropped_before);
}

TEST(RtLog, init_forwards_rt_records_to_stderr_and_shutdown_flushes_them) {
  std::vector<std::string> ignored;
  drain_rt_log_for_test(ignored);

  ::testing::internal::CaptureStderr();
  init_logging(spdlog::level::info);
  init_logging(spdlog::level::info);  // idempotent
  rt_log(RtLogLevel::kWarn, "gap", "short circuit at {:.3f} mm", 1.25);
  spdlog::info("plain non-RT message {}", 42);
  shutdown_logging();  // joins the drain thread and the async writer: everything is out now
  shutdown_logging();  // idempotent
  spdlog::info("after shutdown {}", 7);  // still works, synchronously
  const std::string err = ::testing::internal::GetCapturedStderr();

  EXPECT_NE(err.find("[gap] short circuit at 1.250 mm"), std::string::npos) << err;
  EXPECT_NE(err.find("[warning]"), std::string::npos) << err;
  EXPECT_NE(err.find("plain non-RT message 42"), std::string::npos) << err;
  EXPECT_NE(err.find("after shutdown 7"), std::string::npos) << err;
  std::vector<std::string> left;
  EXPECT_EQ(drain_rt_log_for_test(left), 0u) << "shutdown must forward what was queued";
}

}  // namespace
}  // namespace edm::rt
