#include "edm/blocks/window_ring.hpp"

#include <gtest/gtest.h>

#include <cstddef>

namespace edm::blocks {
namespace {

TEST(WindowRing, fills_then_hands_back_the_oldest_sample) {
  WindowRing<int> r;
  r.allocate(3);
  EXPECT_EQ(r.capacity(), 3u);
  EXPECT_EQ(r.size(), 0u);
  EXPECT_TRUE(r.at_first_slot());
  EXPECT_EQ(r.push(1), 0);  // T{} until full
  EXPECT_EQ(r.push(2), 0);
  EXPECT_FALSE(r.full());
  EXPECT_EQ(r.push(3), 0);
  EXPECT_TRUE(r.full());
  EXPECT_TRUE(r.at_first_slot());  // one whole pass
  EXPECT_EQ(r.push(4), 1);
  EXPECT_EQ(r.push(5), 2);
  EXPECT_FALSE(r.at_first_slot());
  EXPECT_EQ(r.size(), 3u);
}

TEST(WindowRing, indexes_oldest_first_before_and_after_wrapping) {
  WindowRing<int> r;
  r.allocate(4);
  r.push(10);
  r.push(11);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0], 10);
  EXPECT_EQ(r[1], 11);
  for (int x = 12; x < 17; ++x) {
    r.push(x);  // 10..16: the window is 13..16
  }
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(r[i], 13 + static_cast<int>(i));
  }
}

TEST(WindowRing, clear_empties_and_zeroes_the_slots) {
  WindowRing<double> r;
  r.allocate(2);
  r.push(1.5);
  r.push(2.5);
  r.push(3.5);
  r.clear();
  EXPECT_EQ(r.size(), 0u);
  EXPECT_TRUE(r.at_first_slot());
  EXPECT_EQ(r.push(7.0), 0.0);
  EXPECT_EQ(r.push(8.0), 0.0);
  EXPECT_EQ(r.push(9.0), 7.0);
}

TEST(WindowRing, capacity_one_is_the_last_sample) {
  WindowRing<int> r;
  r.allocate(1);
  EXPECT_EQ(r.push(5), 0);
  EXPECT_EQ(r.push(6), 5);
  EXPECT_EQ(r[0], 6);
  EXPECT_TRUE(r.full());
}

TEST(WindowRing, pop_newest_unwinds_and_push_continues_after_it) {
  WindowRing<int> r;
  r.allocate(3);
  for (int x = 1; x <= 4; ++x) {
    r.push(x);  // window 2, 3, 4
  }
  r.pop_newest();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0], 2);
  EXPECT_EQ(r[1], 3);
  r.push(9);
  EXPECT_EQ(r[0], 2);
  EXPECT_EQ(r[2], 9);
  r.push(10);  // full: 2 leaves
  EXPECT_EQ(r[0], 3);
  EXPECT_EQ(r[2], 10);
}

TEST(WindowRing, forget_empties_in_place) {
  WindowRing<int> r;
  r.allocate(2);
  r.push(1);
  r.push(2);
  r.forget();
  EXPECT_EQ(r.size(), 0u);
  r.push(5);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], 5);
}

}  // namespace
}  // namespace edm::blocks
