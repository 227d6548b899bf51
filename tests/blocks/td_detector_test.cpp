#include "edm/blocks/td_detector.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

// One cycle of the FPGA counters.
struct Pulses {
  std::int64_t td_sum_ns{0};
  std::int64_t td_count{0};
  std::int64_t n_open{0};
  std::int64_t n_short{0};
  std::int64_t n_total{0};  // 0: unwired
};

class TdDetectorTest : public ::testing::Test {
 protected:
  std::vector<rt::ParamError> start(const TdDetectorParams& p) {
    auto errs = h_.start(p);
    sum_ = &h_.source<std::int64_t>("td_sum_ns");
    count_ = &h_.source<std::int64_t>("td_count");
    open_ = &h_.source<std::int64_t>("n_open");
    short_ = &h_.source<std::int64_t>("n_short");
    total_ = &h_.source<std::int64_t>("n_total");
    return errs;
  }
  BlockStatus step(const Pulses& c) {
    sum_->set(c.td_sum_ns);
    count_->set(c.td_count);
    open_->set(c.n_open);
    short_->set(c.n_short);
    total_->set(c.n_total);
    return h_.step();
  }
  double td() const { return h_.out("td_us"); }
  double td_raw() const { return h_.out("td_raw_us"); }
  double open_ratio() const { return h_.out("open_ratio"); }
  double short_ratio() const { return h_.out("short_ratio"); }
  bool valid() const { return h_.out<bool>("valid"); }

  BlockHarness<TdDetector> h_;
  rt::Output<std::int64_t>* sum_{nullptr};
  rt::Output<std::int64_t>* count_{nullptr};
  rt::Output<std::int64_t>* open_{nullptr};
  rt::Output<std::int64_t>* short_{nullptr};
  rt::Output<std::int64_t>* total_{nullptr};
};

TEST_F(TdDetectorTest, window_of_one_gives_this_cycles_mean) {
  ASSERT_TRUE(start({.window = 1}).empty());
  EXPECT_EQ(step({.td_sum_ns = 30'000, .td_count = 4}), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(td(), 7.5);  // 30 000 ns / 4 = 7500 ns
  EXPECT_DOUBLE_EQ(td_raw(), 7.5);
  EXPECT_TRUE(valid());
  step({.td_sum_ns = 12'340, .td_count = 1});
  EXPECT_DOUBLE_EQ(td(), 12.34);
  EXPECT_DOUBLE_EQ(td_raw(), 12.34);
}

TEST_F(TdDetectorTest, window_pools_sums_not_means) {
  ASSERT_TRUE(start({.window = 3}).empty());
  // Cycle 1: 2 pulses, 10 µs each. Cycle 2: 8 pulses, 5 µs each. Cycle 3: 10
  // pulses, 2 µs each.
  step({.td_sum_ns = 20'000, .td_count = 2});
  EXPECT_DOUBLE_EQ(td(), 10.0);
  step({.td_sum_ns = 40'000, .td_count = 8});
  EXPECT_DOUBLE_EQ(td(), 6.0);  // 60 000 / 10, not (10 + 5) / 2
  EXPECT_DOUBLE_EQ(td_raw(), 5.0);
  step({.td_sum_ns = 20'000, .td_count = 10});
  EXPECT_DOUBLE_EQ(td(), 4.0);  // 80 000 / 20
  EXPECT_DOUBLE_EQ(td_raw(), 2.0);
  // Cycle 4 pushes cycle 1 out: (40 000 + 20 000 + 9 000) / (8 + 10 + 3) = 69
  // 000 / 21.
  step({.td_sum_ns = 9'000, .td_count = 3});
  EXPECT_DOUBLE_EQ(td(), 69.0 / 21.0);
  EXPECT_DOUBLE_EQ(td_raw(), 3.0);
  // An empty cycle 5 pushes cycle 2 out: (20 000 + 9 000 + 0) / (10 + 3 + 0).
  step({.td_sum_ns = 0, .td_count = 0});
  EXPECT_DOUBLE_EQ(td(), 29.0 / 13.0);
  EXPECT_DOUBLE_EQ(td_raw(), 3.0) << "an empty cycle holds the raw mean";
  EXPECT_TRUE(valid());
}

TEST_F(TdDetectorTest, window_matches_brute_force_over_random_cycles) {
  constexpr std::int64_t kWindow = 7;
  ASSERT_TRUE(start({.window = kWindow}).empty());
  std::mt19937_64 rng(42);  // seeded: reproducible
  std::uniform_int_distribution<std::int64_t> count_dist(0, 40);
  std::uniform_int_distribution<std::int64_t> td_dist(0, 50'000);
  std::vector<Pulses> history;
  double last_td = 0.0;
  for (int k = 0; k < 5000; ++k) {
    Pulses c;
    c.td_count = k % 11 == 0 ? 0 : count_dist(rng);
    for (std::int64_t i = 0; i < c.td_count; ++i) {
      c.td_sum_ns += td_dist(rng) / 10 * 10;
    }
    c.n_open = count_dist(rng) / 4;
    c.n_short = count_dist(rng) / 8;
    history.push_back(c);
    ASSERT_EQ(step(c), BlockStatus::kOk);
    std::int64_t s = 0, n = 0, o = 0, sh = 0, t = 0;
    for (std::size_t i = history.size() > kWindow ? history.size() - kWindow : 0;
         i < history.size(); ++i) {
      s += history[i].td_sum_ns;
      n += history[i].td_count;
      o += history[i].n_open;
      sh += history[i].n_short;
      t += history[i].td_count + history[i].n_open + history[i].n_short;
    }
    // Gap truth: a short is a pulse with Td = short_td_us = 0, pooled with the ignited ones.
    ASSERT_EQ(valid(), n + sh > 0) << "k = " << k;
    if (n + sh > 0) {
      last_td = static_cast<double>(s) / static_cast<double>(n + sh) / 1000.0;
    }
    ASSERT_DOUBLE_EQ(td(), last_td) << "k = " << k;
    if (t > 0) {
      ASSERT_DOUBLE_EQ(open_ratio(), static_cast<double>(o) / static_cast<double>(t));
      ASSERT_DOUBLE_EQ(short_ratio(), static_cast<double>(sh) / static_cast<double>(t));
    }
  }
}

TEST_F(TdDetectorTest, ratios_use_n_total_or_the_sum_of_the_classes) {
  ASSERT_TRUE(start({.window = 2}).empty());
  // n_total unwired: total = 6 ignited + 3 open + 1 short = 10.
  step({.td_sum_ns = 60'000, .td_count = 6, .n_open = 3, .n_short = 1});
  EXPECT_DOUBLE_EQ(open_ratio(), 0.3);
  EXPECT_DOUBLE_EQ(short_ratio(), 0.1);
  // n_total given (e.g. counting pulses of classes this block does not see): 3
  // + 1 of 40.
  step({.td_sum_ns = 10'000, .td_count = 2, .n_open = 3, .n_short = 1, .n_total = 40});
  EXPECT_DOUBLE_EQ(open_ratio(), 6.0 / 50.0);
  EXPECT_DOUBLE_EQ(short_ratio(), 2.0 / 50.0);
  EXPECT_DOUBLE_EQ(td(), 70.0 / 10.0) << "8 ignited and 2 shorts (Td 0)";
  // Only open pulses: no ignition this cycle, but the window still has ignited
  // pulses.
  step({.n_open = 10});
  EXPECT_DOUBLE_EQ(open_ratio(), 13.0 / 50.0);
  EXPECT_DOUBLE_EQ(short_ratio(), 1.0 / 50.0);
  EXPECT_DOUBLE_EQ(td(), 10.0 / 3.0);
  EXPECT_TRUE(valid());
  // All open for the whole window: not valid, Td held, open ratio 1.
  step({.n_open = 10});
  EXPECT_DOUBLE_EQ(open_ratio(), 1.0);
  EXPECT_DOUBLE_EQ(short_ratio(), 0.0);
  EXPECT_FALSE(valid());
  EXPECT_DOUBLE_EQ(td(), 10.0 / 3.0) << "hold_when_empty keeps the last td_us";
}

TEST_F(TdDetectorTest, empty_window_holds_by_default_and_never_divides) {
  ASSERT_TRUE(start({.window = 2, .hold_when_empty = true, .empty_td_us = 99.0}).empty());
  EXPECT_DOUBLE_EQ(td(), 99.0) << "activate() outputs empty_td_us";
  EXPECT_FALSE(valid());
  // No pulses at all before any ignition: nothing to hold yet but empty_td_us.
  EXPECT_EQ(step({}), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(td(), 99.0);
  EXPECT_DOUBLE_EQ(open_ratio(), 0.0);
  EXPECT_FALSE(valid());
  step({.td_sum_ns = 8'000, .td_count = 2, .n_open = 2, .n_short = 4});
  EXPECT_DOUBLE_EQ(td(), 8.0 / 6.0) << "2 ignited (4 us) and 4 shorts (0 us)";
  EXPECT_TRUE(valid());
  EXPECT_EQ(step({}), BlockStatus::kOk);
  EXPECT_TRUE(valid()) << "the ignited cycle is still in the window";
  EXPECT_EQ(step({}),
            BlockStatus::kOk);  // generator off: no pulses in the window
  EXPECT_FALSE(valid());
  EXPECT_DOUBLE_EQ(td(), 8.0 / 6.0);
  EXPECT_DOUBLE_EQ(td_raw(), 8.0 / 6.0);
  EXPECT_DOUBLE_EQ(open_ratio(), 0.25) << "ratios held too";
  EXPECT_DOUBLE_EQ(short_ratio(), 0.5);
}

TEST_F(TdDetectorTest, empty_window_outputs_empty_td_us_when_not_holding) {
  ASSERT_TRUE(start({.window = 1, .hold_when_empty = false, .empty_td_us = 60.0}).empty());
  step({.td_sum_ns = 8'000, .td_count = 2, .n_open = 2, .n_short = 4});
  EXPECT_DOUBLE_EQ(td(), 8.0 / 6.0);
  EXPECT_EQ(step({.n_open = 5}), BlockStatus::kOk);
  EXPECT_FALSE(valid());
  EXPECT_DOUBLE_EQ(td(), 60.0);
  EXPECT_DOUBLE_EQ(td_raw(), 60.0);
  EXPECT_DOUBLE_EQ(open_ratio(), 1.0);
  EXPECT_EQ(step({}), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(open_ratio(), 0.0);
  EXPECT_DOUBLE_EQ(short_ratio(), 0.0);
  EXPECT_DOUBLE_EQ(td(), 60.0);
}

TEST_F(TdDetectorTest, broken_counters_fault_and_are_not_stored) {
  ASSERT_TRUE(start({.window = 4}).empty());
  step({.td_sum_ns = 40'000, .td_count = 4, .n_open = 1, .n_short = 1});
  const double td0 = td();
  const double open0 = open_ratio();
  const std::vector<Pulses> bad = {
      {.td_sum_ns = -1, .td_count = 1},
      {.td_sum_ns = 10, .td_count = -1},
      {.n_open = -3},
      {.n_short = -3},
      {.td_sum_ns = 10'000, .td_count = 1, .n_open = 1, .n_total = -1},
      {.td_sum_ns = 10'000, .td_count = 5, .n_total = 4},  // fewer pulses than ignited
      {.td_sum_ns = 10'000, .td_count = 1, .n_open = 3, .n_short = 3, .n_total = 5},
      {.td_sum_ns = 10'000, .td_count = 0},                     // a delay without a pulse
      {.td_sum_ns = TdDetector::kMaxCount + 1, .td_count = 1},  // would risk overflow
      {.td_sum_ns = 10, .td_count = std::numeric_limits<std::int64_t>::max()},
  };
  for (const Pulses& c : bad) {
    EXPECT_EQ(step(c), BlockStatus::kFault) << c.td_sum_ns << " " << c.td_count;
    EXPECT_EQ(td(), td0);
    EXPECT_EQ(open_ratio(), open0);
    EXPECT_TRUE(valid());
  }
  // The bad cycles never entered the sums.
  EXPECT_EQ(step({.td_sum_ns = 20'000, .td_count = 4}), BlockStatus::kOk);
  EXPECT_DOUBLE_EQ(td(), 60.0 / 9.0) << "8 ignited and the first cycle's short";
  EXPECT_DOUBLE_EQ(open_ratio(), 1.0 / 10.0);
}

TEST_F(TdDetectorTest, activate_empties_the_window) {
  ASSERT_TRUE(start({.window = 4, .hold_when_empty = true, .empty_td_us = 1.0}).empty());
  step({.td_sum_ns = 50'000, .td_count = 1, .n_open = 1});
  EXPECT_DOUBLE_EQ(td(), 50.0);
  h_.block().activate();
  EXPECT_DOUBLE_EQ(td(), 1.0);
  EXPECT_FALSE(valid());
  EXPECT_DOUBLE_EQ(open_ratio(), 0.0);
  step({.td_sum_ns = 2'000, .td_count = 1});
  EXPECT_DOUBLE_EQ(td(), 2.0) << "the cycle before activate() is gone";
  EXPECT_DOUBLE_EQ(open_ratio(), 0.0);
}

TEST_F(TdDetectorTest, validate_and_runtime_writes) {
  EXPECT_TRUE(rt::validate_params(TdDetectorParams{}).empty());
  EXPECT_EQ(TdDetectorParams{}.window, 8);
  EXPECT_TRUE(TdDetectorParams{}.hold_when_empty);
  EXPECT_FALSE(rt::validate_params(TdDetectorParams{.window = 0}).empty());
  EXPECT_FALSE(
      rt::validate_params(TdDetectorParams{.window = TdDetectorParams::kMaxWindow + 1}).empty());
  EXPECT_FALSE((rt::validate_params(TdDetectorParams{.window = 1, .empty_td_us = -1.0}).empty()));
  EXPECT_FALSE(
      (rt::validate_params(
           TdDetectorParams{.window = 1, .empty_td_us = std::numeric_limits<double>::quiet_NaN()})
           .empty()));

  ASSERT_TRUE(start({.window = 2, .hold_when_empty = true}).empty());
  const auto refused = h_.write_param("window", rt::ParamValue::of_int(4));
  ASSERT_EQ(refused.size(), 1u);
  EXPECT_NE(refused[0].message.find("load time only"), std::string::npos) << refused[0].message;
  const auto errs = h_.write_param("hold_when_empty", rt::ParamValue::of_bool(false));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  step({.td_sum_ns = 3'000, .td_count = 1});
  step({});
  EXPECT_DOUBLE_EQ(td(), 3.0);
  step({});
  EXPECT_DOUBLE_EQ(td(), 0.0) << "hold switched off at run time: empty_td_us";
}

// Gap truth (seed 004): a contact reads feedback ≈ 0. A window of nothing but shorts is a valid
// measurement of Td = short_td_us, far below any reference, so a P law backs off.
TEST_F(TdDetectorTest, a_window_of_shorts_reads_short_td_and_is_valid) {
  ASSERT_TRUE(start({.window = 4}).empty());
  for (int k = 0; k < 4; ++k) {
    step({.td_sum_ns = 120'000, .td_count = 10});
  }
  EXPECT_DOUBLE_EQ(td(), 12.0);
  for (int k = 0; k < 4; ++k) {
    step({.n_short = 10});
  }
  EXPECT_TRUE(valid());
  EXPECT_DOUBLE_EQ(td(), 0.0);
  EXPECT_DOUBLE_EQ(td_raw(), 0.0);
  EXPECT_DOUBLE_EQ(short_ratio(), 1.0);
  ASSERT_TRUE(start({.window = 2, .short_td_us = 0.5}).empty());
  step({.td_sum_ns = 30'000, .td_count = 3, .n_short = 1});
  EXPECT_DOUBLE_EQ(td(), (30.0 + 0.5) / 4.0) << "a short counts with short_td_us";
}

}  // namespace
}  // namespace edm::blocks
