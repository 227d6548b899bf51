// Seed 003 discharge-state statistics: three 32-bit shift registers, popcounts, analysis interval.

#include "edm/blocks/discharge_state_counter.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

using PulseClass = DischargeStateCounter::PulseClass;

struct Counts {
  std::int64_t open{0}, normal{0}, shorts{0}, transient{0}, stable{0};
};

class Counter {
 public:
  explicit Counter(std::int64_t interval, bool arcs_as_short = true) {
    EXPECT_TRUE(h_.start({.interval = interval, .arcs_as_short = arcs_as_short}).empty());
    open_ = &h_.source<std::int64_t>("n_open");
    normal_ = &h_.source<std::int64_t>("n_normal");
    short_ = &h_.source<std::int64_t>("n_short");
    transient_ = &h_.source<std::int64_t>("n_transient_arc");
    stable_ = &h_.source<std::int64_t>("n_stable_arc");
  }
  BlockStatus step(const Counts& c) {
    open_->set(c.open);
    normal_->set(c.normal);
    short_->set(c.shorts);
    transient_->set(c.transient);
    stable_->set(c.stable);
    return h_.step();
  }
  std::int64_t open() const { return h_.out<std::int64_t>("open_count"); }
  std::int64_t normal() const { return h_.out<std::int64_t>("normal_count"); }
  std::int64_t shorts() const { return h_.out<std::int64_t>("short_count"); }
  std::int64_t latches() const { return h_.out<std::int64_t>("latches"); }
  bool ready() const { return h_.out<bool>("data_ready"); }
  DischargeStateCounter& block() { return h_.block(); }

 private:
  BlockHarness<DischargeStateCounter> h_;
  rt::Output<std::int64_t>* open_{nullptr};
  rt::Output<std::int64_t>* normal_{nullptr};
  rt::Output<std::int64_t>* short_{nullptr};
  rt::Output<std::int64_t>* transient_{nullptr};
  rt::Output<std::int64_t>* stable_{nullptr};
};

// The paper's circuit, one pulse at a time: shift registers, popcount, a latch every m pulses.
struct NaiveCircuit {
  std::uint32_t reg[3]{0, 0, 0};
  std::int64_t m;
  std::int64_t since{0};
  std::int64_t latched[3]{0, 0, 0};
  std::int64_t latches_this_cycle{0};

  explicit NaiveCircuit(std::int64_t interval) : m(interval) {}
  void pulse(PulseClass c) {
    for (int k = 0; k < 3; ++k) {
      reg[k] = static_cast<std::uint32_t>(reg[k] << 1) | (k == static_cast<int>(c) ? 1u : 0u);
    }
    if (++since == m) {
      since = 0;
      ++latches_this_cycle;
      for (int k = 0; k < 3; ++k) {
        latched[k] = std::popcount(reg[k]);
      }
    }
  }
};

TEST(DischargeStateCounter, interleaving_enters_every_class_exactly_its_count_and_evenly) {
  std::mt19937_64 rng(1234);
  std::uniform_int_distribution<std::int64_t> count(0, 120);
  for (int trial = 0; trial < 3000; ++trial) {
    const std::int64_t o = count(rng), n = count(rng), s = count(rng);
    const std::int64_t total = o + n + s;
    if (total == 0) {
      continue;
    }
    std::vector<int> cls(static_cast<std::size_t>(total));
    std::int64_t seen[3]{0, 0, 0};
    for (std::int64_t i = 0; i < total; ++i) {
      cls[static_cast<std::size_t>(i)] =
          static_cast<int>(DischargeStateCounter::pulse_class(i, o, n, s));
      ++seen[cls[static_cast<std::size_t>(i)]];
    }
    ASSERT_EQ(seen[0], o);
    ASSERT_EQ(seen[1], n);
    ASSERT_EQ(seen[2], s);
    // Any 32 consecutive pulses of the cycle hold each class within ±2 of its share.
    const std::int64_t want[3] = {o, n, s};
    for (std::int64_t start = 0; start + 32 <= total; ++start) {
      std::int64_t w[3]{0, 0, 0};
      for (std::int64_t i = start; i < start + 32; ++i) {
        ++w[cls[static_cast<std::size_t>(i)]];
      }
      for (int c = 0; c < 3; ++c) {
        const double share = 32.0 * static_cast<double>(want[c]) / static_cast<double>(total);
        ASSERT_LE(std::abs(static_cast<double>(w[c]) - share), 2.0)
            << "o n s = " << o << " " << n << " " << s << ", class " << c << ", start " << start;
      }
    }
  }
}

TEST(DischargeStateCounter, matches_the_pulse_by_pulse_circuit_for_random_counts_and_intervals) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 60; ++trial) {
    const std::int64_t m = std::uniform_int_distribution<std::int64_t>(1, 70)(rng);
    Counter blk(m);
    NaiveCircuit ref(m);
    std::int64_t pulses = 0;
    for (int cycle = 0; cycle < 200; ++cycle) {
      // Mostly small cycles, sometimes empty, sometimes far more than 32 pulses.
      const std::int64_t hi = cycle % 17 == 0 ? 200 : 12;
      std::uniform_int_distribution<std::int64_t> d(0, hi);
      const Counts c{d(rng) / 2, d(rng), d(rng) / 3, d(rng) / 8, d(rng) / 16};
      ASSERT_EQ(blk.step(c), BlockStatus::kOk);
      ref.latches_this_cycle = 0;
      const std::int64_t s = c.shorts + c.transient + c.stable;
      const std::int64_t total = c.open + c.normal + s;
      for (std::int64_t i = 0; i < total; ++i) {
        ref.pulse(DischargeStateCounter::pulse_class(i, c.open, c.normal, s));
      }
      pulses += total;
      ASSERT_EQ(blk.block().open_register(), ref.reg[0]) << "trial " << trial << " cycle " << cycle;
      ASSERT_EQ(blk.block().normal_register(), ref.reg[1]);
      ASSERT_EQ(blk.block().short_register(), ref.reg[2]);
      ASSERT_EQ(blk.latches(), ref.latches_this_cycle);
      ASSERT_EQ(blk.ready(), ref.latches_this_cycle > 0);
      ASSERT_EQ(blk.open(), ref.latched[0]);
      ASSERT_EQ(blk.normal(), ref.latched[1]);
      ASSERT_EQ(blk.shorts(), ref.latched[2]);
      // The registers are exclusive and, once 32 pulses were seen, their counts sum to 32.
      EXPECT_EQ(blk.block().open_register() & blk.block().normal_register(), 0u);
      EXPECT_EQ(blk.block().open_register() & blk.block().short_register(), 0u);
      EXPECT_EQ(blk.block().normal_register() & blk.block().short_register(), 0u);
      const int live = std::popcount(blk.block().open_register()) +
                       std::popcount(blk.block().normal_register()) +
                       std::popcount(blk.block().short_register());
      ASSERT_EQ(live, std::min<std::int64_t>(32, pulses));
    }
  }
}

TEST(DischargeStateCounter, interval_32_latches_only_new_pulses) {
  // One pulse per cycle with a known pattern: every latched window holds exactly the 32 pulses
  // that arrived since the previous latch.
  Counter blk(32);
  std::deque<int> since_latch;
  int latches = 0;
  for (int k = 0; k < 32 * 20; ++k) {
    const int c = (k * 7 + k / 5) % 3;  // a deterministic, irregular pattern
    ASSERT_EQ(blk.step({c == 0 ? 1 : 0, c == 1 ? 1 : 0, c == 2 ? 1 : 0, 0, 0}), BlockStatus::kOk);
    since_latch.push_back(c);
    if (since_latch.size() == 32) {
      ASSERT_TRUE(blk.ready()) << "k = " << k;
      ++latches;
      std::int64_t want[3]{0, 0, 0};
      for (int x : since_latch) {
        ++want[x];
      }
      EXPECT_EQ(blk.open(), want[0]);
      EXPECT_EQ(blk.normal(), want[1]);
      EXPECT_EQ(blk.shorts(), want[2]);
      EXPECT_EQ(blk.open() + blk.normal() + blk.shorts(), 32);
      since_latch.clear();
    } else {
      ASSERT_FALSE(blk.ready()) << "k = " << k;
    }
  }
  EXPECT_EQ(latches, 20);
}

TEST(DischargeStateCounter, interval_1_latches_every_cycle_with_pulses_and_holds_on_empty_ones) {
  Counter blk(1);
  ASSERT_EQ(blk.step({5, 0, 0, 0, 0}), BlockStatus::kOk);
  EXPECT_TRUE(blk.ready());
  EXPECT_EQ(blk.latches(), 5);
  EXPECT_EQ(blk.open(), 5);
  EXPECT_EQ(blk.normal() + blk.shorts(), 0) << "only 5 pulses seen so far";
  ASSERT_EQ(blk.step({}), BlockStatus::kOk);
  EXPECT_FALSE(blk.ready());
  EXPECT_EQ(blk.latches(), 0);
  EXPECT_EQ(blk.open(), 5) << "latched values held";
  ASSERT_EQ(blk.step({0, 0, 40, 0, 0}), BlockStatus::kOk);
  EXPECT_EQ(blk.shorts(), 32) << "40 shorts push every open pulse out";
  EXPECT_EQ(blk.open(), 0);
}

TEST(DischargeStateCounter, arcs_count_as_short_by_default_or_as_normal) {
  Counter as_short(32);
  ASSERT_EQ(as_short.step({0, 10, 2, 12, 8}), BlockStatus::kOk);
  EXPECT_EQ(as_short.normal(), 10);
  EXPECT_EQ(as_short.shorts(), 22);
  Counter as_normal(32, false);
  ASSERT_EQ(as_normal.step({0, 10, 2, 12, 8}), BlockStatus::kOk);
  EXPECT_EQ(as_normal.normal(), 30);
  EXPECT_EQ(as_normal.shorts(), 2);
}

TEST(DischargeStateCounter, broken_counters_fault_and_change_nothing) {
  Counter blk(4);
  ASSERT_EQ(blk.step({3, 1, 0, 0, 0}), BlockStatus::kOk);
  const std::uint32_t reg = blk.block().open_register();
  const std::int64_t open = blk.open();
  EXPECT_EQ(blk.step({-1, 0, 0, 0, 0}), BlockStatus::kFault);
  EXPECT_EQ(blk.step({0, DischargeStateCounter::kMaxCount + 1, 0, 0, 0}), BlockStatus::kFault);
  EXPECT_EQ(blk.step({0, 0, 0, -5, 0}), BlockStatus::kFault);
  EXPECT_EQ(blk.block().open_register(), reg);
  EXPECT_EQ(blk.open(), open);
}

TEST(DischargeStateCounter, huge_cycles_cost_two_windows_and_keep_the_sum) {
  // 10^8 pulses in one cycle must not loop over them; the window holds the proportional mix.
  Counter blk(1000);
  ASSERT_EQ(blk.step({50'000'000, 25'000'000, 25'000'000, 0, 0}), BlockStatus::kOk);
  EXPECT_TRUE(blk.ready());
  EXPECT_EQ(blk.latches(), 100'000);
  EXPECT_EQ(blk.open() + blk.normal() + blk.shorts(), 32);
  EXPECT_NEAR(static_cast<double>(blk.open()), 16.0, 2.0);
  EXPECT_NEAR(static_cast<double>(blk.normal()), 8.0, 2.0);
}

TEST(DischargeStateCounter, validate_refuses_a_zero_interval) {
  EXPECT_FALSE(rt::validate_params(DischargeStateCounterParams{.interval = 0}).empty());
  EXPECT_TRUE(rt::validate_params(DischargeStateCounterParams{}).empty());
}

}  // namespace
}  // namespace edm::blocks
