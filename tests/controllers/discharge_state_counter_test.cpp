// Seed 003 discharge-state statistics (Liu 2011, §1): three 32-bit shift registers read from the
// generator's last-32 class bitmasks, popcounts, the analysis interval m.
//
// The reference here is a list of pulses: a generator that keeps the bitmasks the way the
// simulator's plant does (sim/src/plant.cpp: shift left, the new pulse's class into bit 0), and
// the counts recomputed from the list's newest 32 entries, not from bits.

#include "edm/blocks/discharge_state_counter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

enum Cls : int { kOpen, kNormal, kShort, kTransient, kStable };

// The generator: the pulse list and the plant's three history bitmasks.
struct Generator {
  std::vector<int> pulses;  // every pulse ever, oldest first
  std::uint32_t hist_open{0}, hist_short{0}, hist_arc{0};
  std::int64_t count[5]{0, 0, 0, 0, 0};  // this cycle

  void begin_cycle() { std::fill(std::begin(count), std::end(count), 0); }
  void pulse(int c) {
    pulses.push_back(c);
    ++count[c];
    hist_open = (hist_open << 1) | (c == kOpen ? 1U : 0U);
    hist_short = (hist_short << 1) | (c == kShort ? 1U : 0U);
    hist_arc = (hist_arc << 1) | (c == kTransient || c == kStable ? 1U : 0U);
  }
};

class Counter {
 public:
  explicit Counter(std::int64_t interval, bool arcs_as_short = true) {
    h_.start_ok({.interval = interval, .arcs_as_short = arcs_as_short});
    for (const char* n : {"hist_open", "hist_short", "hist_arc", "n_open", "n_normal", "n_short",
                          "n_transient_arc", "n_stable_arc"}) {
      src_.push_back(&h_.source<std::int64_t>(n));
    }
  }
  BlockStatus step(std::int64_t ho, std::int64_t hs, std::int64_t ha, const std::int64_t (&n)[5]) {
    const std::int64_t v[8] = {ho, hs, ha, n[0], n[1], n[2], n[3], n[4]};
    for (std::size_t i = 0; i < 8; ++i) {
      src_[i]->set(v[i]);
    }
    return h_.step();
  }
  BlockStatus step(const Generator& g) {
    return step(g.hist_open, g.hist_short, g.hist_arc, g.count);
  }
  std::int64_t open() const { return h_.out<std::int64_t>("open_count"); }
  std::int64_t normal() const { return h_.out<std::int64_t>("normal_count"); }
  std::int64_t shorts() const { return h_.out<std::int64_t>("short_count"); }
  bool ready() const { return h_.out<bool>("data_ready"); }
  DischargeStateCounter& block() { return h_.block(); }

 private:
  BlockHarness<DischargeStateCounter> h_;
  std::vector<rt::Output<std::int64_t>*> src_;
};

TEST(DischargeStateCounter, latched_counts_are_the_classes_of_the_newest_32_pulses) {
  // Random pulse streams with random cycle sizes (empty, a few, far more than 32) and random m.
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 80; ++trial) {
    const std::int64_t m = std::uniform_int_distribution<std::int64_t>(1, 90)(rng);
    const bool arcs_as_short = trial % 3 != 0;
    Counter blk(m, arcs_as_short);
    Generator gen;
    // A class mix that drifts per trial, so some windows are all-open or all-short.
    std::discrete_distribution<int> mix({double(trial % 5), 3.0, double(trial % 4), 0.5, 0.3});
    std::size_t last_latch_end = 0;  // pulses seen at the previous latch
    for (int cycle = 0; cycle < 150; ++cycle) {
      gen.begin_cycle();
      const int hi = cycle % 13 == 0 ? 120 : 30;
      const int t = std::uniform_int_distribution<int>(0, hi)(rng);
      for (int i = 0; i < t; ++i) {
        gen.pulse(mix(rng));
      }
      const std::int64_t before[3] = {blk.open(), blk.normal(), blk.shorts()};
      ASSERT_EQ(blk.step(gen), BlockStatus::kOk);
      const std::size_t seen = gen.pulses.size();
      const bool want_latch = t > 0 && seen - last_latch_end >= static_cast<std::size_t>(m);
      ASSERT_EQ(blk.ready(), want_latch) << "trial " << trial << " cycle " << cycle;
      if (!want_latch) {
        EXPECT_EQ(blk.open(), before[0]) << "outputs held between latches";
        EXPECT_EQ(blk.normal(), before[1]);
        EXPECT_EQ(blk.shorts(), before[2]);
        continue;
      }
      // The newest min(32, seen) pulses of the list, by class.
      std::int64_t want[3]{0, 0, 0};
      const std::size_t window = std::min<std::size_t>(32, seen);
      for (std::size_t k = seen - window; k < seen; ++k) {
        const int c = gen.pulses[k];
        const bool arc = c == kTransient || c == kStable;
        ++want[c == kOpen ? 0 : (c == kShort || (arc && arcs_as_short)) ? 2 : 1];
      }
      ASSERT_EQ(blk.open(), want[0]) << "trial " << trial << " cycle " << cycle;
      ASSERT_EQ(blk.normal(), want[1]);
      ASSERT_EQ(blk.shorts(), want[2]);
      // The paper's invariant: the three counts sum to 32 (once 32 pulses were seen).
      ASSERT_EQ(blk.open() + blk.normal() + blk.shorts(), static_cast<std::int64_t>(window));
      // Latches are m … m + T − 1 pulses apart; m ≥ 32: the window holds only new pulses.
      ASSERT_LT(seen - last_latch_end, static_cast<std::size_t>(m + t));
      if (m >= 32 && last_latch_end > 0) {
        ASSERT_GE(seen - window, last_latch_end) << "a pulse of the previous window was reused";
      }
      last_latch_end = seen;
      // The registers are exclusive.
      EXPECT_EQ(blk.block().open_register() & blk.block().normal_register(), 0U);
      EXPECT_EQ(blk.block().open_register() & blk.block().short_register(), 0U);
      EXPECT_EQ(blk.block().normal_register() & blk.block().short_register(), 0U);
    }
  }
}

TEST(DischargeStateCounter, registers_start_cleared_whatever_the_driver_remembers) {
  // The generator ran before activate(): its bitmasks carry 32 old shorts. The paper's registers
  // are cleared at reset, so after 5 new open pulses the counts are 5 open and nothing else.
  Generator gen;
  for (int i = 0; i < 32; ++i) {
    gen.pulse(kShort);
  }
  Counter blk(1);
  gen.begin_cycle();
  for (int i = 0; i < 5; ++i) {
    gen.pulse(kOpen);
  }
  ASSERT_EQ(blk.step(gen), BlockStatus::kOk);
  EXPECT_TRUE(blk.ready());
  EXPECT_EQ(blk.open(), 5);
  EXPECT_EQ(blk.normal() + blk.shorts(), 0);
  gen.begin_cycle();
  for (int i = 0; i < 30; ++i) {
    gen.pulse(kNormal);
  }
  ASSERT_EQ(blk.step(gen), BlockStatus::kOk);
  EXPECT_EQ(blk.open(), 2) << "3 of the 5 opens shifted out past bit 31";
  EXPECT_EQ(blk.normal(), 30);
  EXPECT_EQ(blk.shorts(), 0);
}

TEST(DischargeStateCounter, arcs_count_as_short_by_default_or_as_normal) {
  Generator gen;
  gen.begin_cycle();
  for (int c : {kNormal, kTransient, kStable, kShort, kOpen, kTransient}) {
    for (int i = 0; i < 5; ++i) {
      gen.pulse(c);
    }
  }
  Counter as_short(32);
  ASSERT_EQ(as_short.step(gen), BlockStatus::kOk);  // 30 pulses < m: no latch yet
  EXPECT_FALSE(as_short.ready());
  gen.begin_cycle();
  gen.pulse(kNormal);
  gen.pulse(kNormal);
  ASSERT_EQ(as_short.step(gen), BlockStatus::kOk);
  ASSERT_TRUE(as_short.ready());
  EXPECT_EQ(as_short.open(), 5);
  EXPECT_EQ(as_short.shorts(), 20);
  EXPECT_EQ(as_short.normal(), 7);
  Counter as_normal(1, false);
  ASSERT_EQ(as_normal.step(gen), BlockStatus::kOk);
  EXPECT_EQ(as_normal.shorts(), 0) << "only 2 pulses seen by this block";
  EXPECT_EQ(as_normal.normal(), 2);
}

TEST(DischargeStateCounter, broken_signals_fault_and_change_nothing) {
  Counter blk(1);
  const std::int64_t none[5] = {0, 0, 0, 0, 0};
  const std::int64_t three[5] = {3, 0, 0, 0, 0};
  ASSERT_EQ(blk.step(0b111, 0, 0, three), BlockStatus::kOk);
  const std::uint32_t reg = blk.block().open_register();
  ASSERT_EQ(blk.open(), 3);
  const std::int64_t negative[5] = {0, -1, 0, 0, 0};
  const std::int64_t huge[5] = {0, DischargeStateCounter::kMaxCount + 1, 0, 0, 0};
  EXPECT_EQ(blk.step(0b1111, 0, 0, negative), BlockStatus::kFault);
  EXPECT_EQ(blk.step(0b1111, 0, 0, huge), BlockStatus::kFault);
  EXPECT_EQ(blk.step(-1, 0, 0, three), BlockStatus::kFault) << "negative bitmask";
  EXPECT_EQ(blk.step(std::int64_t{1} << 32, 0, 0, three), BlockStatus::kFault) << "bit 32";
  EXPECT_EQ(blk.step(0b1, 0b1, 0, three), BlockStatus::kFault) << "open and short at once";
  EXPECT_EQ(blk.step(0, 0b10, 0b10, three), BlockStatus::kFault) << "short and arc at once";
  EXPECT_EQ(blk.step(0b100, 0, 0b100, three), BlockStatus::kFault) << "open and arc at once";
  EXPECT_EQ(blk.block().open_register(), reg);
  EXPECT_EQ(blk.open(), 3);
  EXPECT_EQ(blk.step(0b111, 0, 0, none), BlockStatus::kOk) << "no pulse: nothing to latch";
  EXPECT_FALSE(blk.ready());
  EXPECT_EQ(blk.open(), 3);
}

TEST(DischargeStateCounter, validate_refuses_a_zero_interval) {
  EXPECT_FALSE(rt::validate_params(DischargeStateCounterParams{.interval = 0}).empty());
  EXPECT_TRUE(rt::validate_params(DischargeStateCounterParams{}).empty());
}

}  // namespace
}  // namespace edm::blocks
