// JobStore: the runtime-owned part program and its RT cursor.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "edm/runtime/job.hpp"

namespace edm::rt {
namespace {

using machining::MotionBlock;
using machining::MotionKind;

std::vector<MotionBlock> program(int n, int tag) {
  std::vector<MotionBlock> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    p[static_cast<std::size_t>(i)].kind = MotionKind::kDwell;
    p[static_cast<std::size_t>(i)].line = tag * 1000 + i + 1;
    p[static_cast<std::size_t>(i)].condition = tag;
  }
  return p;
}

TEST(JobStore, RunsTheLoadedProgramBlockByBlock) {
  JobStore s;
  EXPECT_FALSE(s.rt_begin()) << "nothing loaded";
  ASSERT_EQ(s.load(program(3, 1)), LoadResult::kOk);
  EXPECT_EQ(s.loaded_blocks(), 3u);
  EXPECT_EQ(s.rt_current(), nullptr) << "no job active";
  ASSERT_TRUE(s.rt_begin());
  EXPECT_FALSE(s.rt_begin()) << "already active";
  for (int i = 0; i < 3; ++i) {
    const MotionBlock* b = s.rt_current();
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->line, 1000 + i + 1);
    EXPECT_EQ(s.progress().block_index, static_cast<std::size_t>(i));
    EXPECT_EQ(s.progress().line, 1000 + i + 1);
    s.rt_advance();
  }
  EXPECT_EQ(s.rt_current(), nullptr) << "past the end";
  EXPECT_EQ(s.progress().outcome, JobOutcome::kRunning);
  s.rt_finish(JobOutcome::kFinished);
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.progress().outcome, JobOutcome::kFinished);
  EXPECT_EQ(s.progress().block_index, 3u);
  // The same program can run again.
  ASSERT_TRUE(s.rt_begin());
  EXPECT_EQ(s.rt_current()->line, 1001);
  EXPECT_EQ(s.progress().jobs_started, 2u);
}

TEST(JobStore, LoadIsRefusedWhileAJobIsActiveAndKeepsTheProgram) {
  JobStore s;
  ASSERT_EQ(s.load(program(2, 1)), LoadResult::kOk);
  ASSERT_TRUE(s.rt_begin());
  s.rt_advance();
  EXPECT_EQ(s.load(program(5, 2)), LoadResult::kBusy);
  ASSERT_NE(s.rt_current(), nullptr);
  EXPECT_EQ(s.rt_current()->line, 1002) << "the running job is untouched";
  EXPECT_EQ(s.loaded_blocks(), 2u);
  s.rt_finish(JobOutcome::kAborted);
  EXPECT_EQ(s.progress().outcome, JobOutcome::kAborted);
  EXPECT_EQ(s.load(program(5, 2)), LoadResult::kOk);
  EXPECT_EQ(s.loaded_blocks(), 5u);
  EXPECT_EQ(s.progress().outcome, JobOutcome::kNone);
  EXPECT_EQ(s.progress().generation, 2u);
}

TEST(JobStore, EmptyProgramNeverStarts) {
  JobStore s;
  ASSERT_EQ(s.load({}), LoadResult::kOk);
  EXPECT_FALSE(s.rt_begin());
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.load(program(1, 1)), LoadResult::kOk) << "a failed begin leaves the store idle";
}

// A loader thread swaps programs as fast as it can while an RT thread starts, walks and finishes
// jobs: every job the RT side sees is one whole program (all blocks carry the same tag), and
// loads only succeed between jobs. Run under TSan by ./edm tsan.
TEST(JobStore, ConcurrentLoadsNeverTearARunningJob) {
  JobStore s;
  ASSERT_EQ(s.load(program(4, 1)), LoadResult::kOk);
  std::atomic<bool> stop{false};
  std::atomic<int> loads{0};
  std::thread loader([&] {
    int tag = 2;
    while (!stop.load(std::memory_order_relaxed)) {
      if (s.load(program(1 + tag % 7, tag)) == LoadResult::kOk) {
        loads.fetch_add(1, std::memory_order_relaxed);
        ++tag;
      }
    }
  });
  int jobs = 0;
  int torn = 0;
  // Until both sides have made progress (on a loaded machine the loader may win the first 20000
  // tries); the deadline only bounds a broken store.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (int k = 0;
       (k < 20000 || loads.load() < 10 || jobs == 0) && std::chrono::steady_clock::now() < deadline;
       ++k) {
    if (!s.rt_begin()) continue;
    ++jobs;
    const MotionBlock* first = s.rt_current();
    const int tag = first->condition;
    while (const MotionBlock* b = s.rt_current()) {
      if (b->condition != tag) ++torn;
      s.rt_advance();
    }
    s.rt_finish(JobOutcome::kFinished);
  }
  stop.store(true);
  loader.join();
  EXPECT_EQ(torn, 0);
  EXPECT_GT(jobs, 0);
  EXPECT_GE(loads.load(), 10);
}

}  // namespace
}  // namespace edm::rt
