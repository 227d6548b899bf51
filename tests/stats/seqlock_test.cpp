#include "edm/runtime/seqlock.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

namespace edm::rt {
namespace {

// 5 words plus a 4-byte tail: more than one word, and a size that is not a multiple of 8.
struct Sample {
  std::array<std::uint64_t, 5> words{};
  std::uint32_t tail{0};
};

Sample sample(std::uint64_t n) {
  Sample s;
  s.words.fill(n);
  s.tail = static_cast<std::uint32_t>(n);
  return s;
}

TEST(Seqlock, starts_with_the_initial_value_at_version_zero) {
  const Seqlock<Sample> lock(sample(7));
  EXPECT_EQ(lock.version(), 0u);
  EXPECT_EQ(lock.load().words[4], 7u);
  EXPECT_EQ(lock.load().tail, 7u);
}

TEST(Seqlock, store_publishes_and_advances_the_version_by_two) {
  Seqlock<Sample> lock;
  lock.store(sample(3));
  Sample out;
  ASSERT_TRUE(lock.try_load(out));
  EXPECT_EQ(out.words[0], 3u);
  EXPECT_EQ(out.tail, 3u);
  EXPECT_EQ(lock.version(), 2u);
}

TEST(Seqlock, reset_replaces_the_value_and_keeps_the_version_even_and_advanced) {
  Seqlock<Sample> lock;
  lock.store(sample(3));
  lock.reset(sample(0));
  EXPECT_EQ(lock.load().words[2], 0u);
  EXPECT_EQ(lock.version() % 2, 0u);
  EXPECT_GT(lock.version(), 2u);
}

// The writer never waits; a reader never sees words of two different stores, nor goes back.
TEST(Seqlock, concurrent_loads_are_never_torn_nor_older) {
  Seqlock<Sample> lock;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 1; n <= 200'000; ++n) {
      lock.store(sample(n));
    }
    done.store(true);
  });
  std::uint64_t last = 0;
  std::uint64_t reads = 0;
  do {
    const Sample s = lock.load();
    for (std::uint64_t w : s.words) {
      ASSERT_EQ(w, s.words[0]);
    }
    ASSERT_EQ(s.tail, static_cast<std::uint32_t>(s.words[0]));
    ASSERT_GE(s.words[0], last);
    last = s.words[0];
    ++reads;
  } while (!done.load());
  writer.join();
  EXPECT_EQ(lock.load().words[0], 200'000u);
  EXPECT_GT(reads, 0u);
}

}  // namespace
}  // namespace edm::rt
