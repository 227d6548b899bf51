// StatusBoard on rt::Seqlock (issue 32, item 5): a writer publishes while readers sample, and no
// reader ever sees a torn snapshot (one whose fields come from two publications) or an older one
// than it saw before. Every field of publication n is derived from n, so a torn copy shows.
#include "edm/bridge/status_board.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <latch>
#include <thread>
#include <vector>

namespace edm::bridge::test {
namespace {

constexpr std::uint64_t kPublications = 100'000;
constexpr int kReaders = 3;

/// The value pin i carries in publication n.
double pin_value(std::uint64_t n, std::size_t i) {
  return static_cast<double>(n * kMaxStatusVars + i);
}

/// True when every field of `s` belongs to the same publication.
bool consistent(const StatusSnapshot& s) {
  const std::uint64_t n = s.publication;
  if (s.cycle != n || s.release != rt::TimePoint{static_cast<std::int64_t>(n)}) return false;
  if (s.n_vars != kMaxStatusVars) return false;
  for (std::size_t i = 0; i < kMaxStatusVars; ++i) {
    if (s.vars[i] != pin_value(n, i)) return false;
  }
  return true;
}

TEST(StatusBoard, reads_nothing_before_the_first_publication_then_the_latest) {
  rt::Machine machine;
  rt::JobStore job;
  rt::Output<double> pin{4.5};
  StatusBoard board(machine, job, {rt::PinRef::of(pin)});
  StatusSnapshot s;
  s.cycle = 77;
  EXPECT_FALSE(board.read(s));
  EXPECT_EQ(s.cycle, 77u) << "untouched when nothing was published";
  board.publish_now(rt::TimePoint{10}, 3);
  pin.set(-1.0);
  board.publish_now(rt::TimePoint{20}, 4);
  ASSERT_TRUE(board.read(s));
  EXPECT_EQ(s.publication, 2u);
  EXPECT_EQ(s.cycle, 4u);
  EXPECT_EQ(s.release, rt::TimePoint{20});
  EXPECT_EQ(s.n_vars, 1u);
  EXPECT_EQ(s.vars[0], -1.0);
  EXPECT_EQ(s.state, machine.state());
}

TEST(StatusBoard, more_pins_than_the_board_holds_are_refused) {
  rt::Machine machine;
  rt::JobStore job;
  rt::Output<double> pin;
  const std::vector<rt::PinRef> pins(kMaxStatusVars + 1, rt::PinRef::of(pin));
  EXPECT_THROW(StatusBoard(machine, job, pins), std::invalid_argument);
}

TEST(StatusBoard, concurrent_readers_never_see_a_torn_or_older_snapshot) {
  rt::Machine machine;
  rt::JobStore job;
  std::array<rt::Output<double>, kMaxStatusVars> pins;
  std::vector<rt::PinRef> refs;
  for (auto& p : pins) refs.push_back(rt::PinRef::of(p));
  StatusBoard board(machine, job, refs);

  std::latch start(kReaders + 1);  // every thread runs before the first publication
  std::atomic<std::uint64_t> torn{0};
  std::atomic<std::uint64_t> older{0};
  std::atomic<std::uint64_t> reads{0};
  std::atomic<std::uint64_t> mid_run{0};  // reads that saw neither nothing nor the last one
  std::thread writer([&] {
    start.arrive_and_wait();
    for (std::uint64_t n = 1; n <= kPublications; ++n) {
      for (std::size_t i = 0; i < kMaxStatusVars; ++i) pins[i].set(pin_value(n, i));
      board.publish_now(rt::TimePoint{static_cast<std::int64_t>(n)}, n);
    }
  });
  std::vector<std::thread> readers;
  for (int r = 0; r < kReaders; ++r) {
    readers.emplace_back([&] {
      start.arrive_and_wait();
      std::uint64_t last = 0;
      StatusSnapshot s;
      while (last < kPublications) {  // ends: the writer's last publication stays
        if (!board.read(s)) continue;
        if (!consistent(s)) torn.fetch_add(1);
        if (s.publication < last) older.fetch_add(1);
        if (s.publication < kPublications) mid_run.fetch_add(1);
        last = s.publication;
        reads.fetch_add(1);
      }
    });
  }
  writer.join();
  for (auto& t : readers) t.join();
  EXPECT_EQ(torn.load(), 0u);
  EXPECT_EQ(older.load(), 0u);
  EXPECT_GE(reads.load(), static_cast<std::uint64_t>(kReaders));
  std::printf("status board: %llu reads, %llu while the writer ran\n",
              static_cast<unsigned long long>(reads.load()),
              static_cast<unsigned long long>(mid_run.load()));
  StatusSnapshot s;
  ASSERT_TRUE(board.read(s));
  EXPECT_EQ(s.publication, kPublications);
  EXPECT_TRUE(consistent(s));
}

}  // namespace
}  // namespace edm::bridge::test
