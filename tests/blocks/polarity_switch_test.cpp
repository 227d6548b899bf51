#include "edm/blocks/polarity_switch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>
#include <vector>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

using rt::Duration;

struct Out {
  bool positive;
  bool gen_on;
  bool switching;
};

// Runs at 1 ms per cycle: a settle of 20ms is 20 cycles.
class PolaritySwitchTest : public ::testing::Test {
 protected:
  void start(const PolaritySwitchParams& p) {
    const auto errs = h_.start(p);
    ASSERT_TRUE(errs.empty()) << describe(errs);
    request_ = &h_.source<bool>("request_positive");
    gen_request_ = &h_.source<bool>("generator_on_request");
  }
  Out step(bool request_positive, bool generator_on_request) {
    request_->set(request_positive);
    gen_request_->set(generator_on_request);
    EXPECT_EQ(h_.step(), BlockStatus::kOk);
    return {h_.out<bool>("polarity_positive"), h_.out<bool>("generator_on"),
            h_.out<bool>("switching")};
  }
  // Steps `n` cycles with the same inputs; every cycle must give `expect`.
  void run(int n, bool request_positive, bool generator_on_request, Out expect) {
    for (int i = 0; i < n; ++i) {
      const Out o = step(request_positive, generator_on_request);
      ASSERT_EQ(o.positive, expect.positive) << "cycle " << h_.cycle() - 1;
      ASSERT_EQ(o.gen_on, expect.gen_on) << "cycle " << h_.cycle() - 1;
      ASSERT_EQ(o.switching, expect.switching) << "cycle " << h_.cycle() - 1;
    }
  }

  BlockHarness<PolaritySwitch> h_{1ms};
  rt::Output<bool>* request_{nullptr};
  rt::Output<bool>* gen_request_{nullptr};
};

TEST_F(PolaritySwitchTest, generator_waits_one_settle_after_activation) {
  start({.settle = 20ms, .initial_positive = false});
  EXPECT_FALSE(h_.out<bool>("polarity_positive"));
  EXPECT_FALSE(h_.out<bool>("generator_on"));
  EXPECT_TRUE(h_.out<bool>("switching"));
  run(20, false, true, {.positive = false, .gen_on = false, .switching = true});
  run(1, false, true, {.positive = false, .gen_on = true, .switching = false});
  EXPECT_EQ(h_.cycle(), 21u);
}

TEST_F(PolaritySwitchTest, initial_positive_sets_the_polarity_after_activation) {
  start({.settle = 5ms, .initial_positive = true});
  EXPECT_TRUE(h_.out<bool>("polarity_positive"));
  run(5, true, true, {.positive = true, .gen_on = false, .switching = true});
  run(1, true, true, {.positive = true, .gen_on = true, .switching = false});
}

TEST_F(PolaritySwitchTest, switch_timing_is_exactly_settle_off_before_and_after) {
  start({.settle = 20ms});
  run(20, false, true, {.positive = false, .gen_on = false, .switching = true});  // 0..19
  run(10, false, true, {.positive = false, .gen_on = true, .switching = false});  // 20..29
  ASSERT_TRUE(step(false, true).gen_on);                                          // 30
  // Cycle 31: positive requested. Generator off at once, polarity unchanged for
  // 20 cycles.
  run(20, true, true, {.positive = false, .gen_on = false, .switching = true});  // 31..50
  // Cycle 51 = 31 + 20: switch, generator still off for 20 more cycles.
  run(20, true, true, {.positive = true, .gen_on = false, .switching = true});  // 51..70
  // Cycle 71: the generator follows its request again.
  run(5, true, true, {.positive = true, .gen_on = true, .switching = false});
}

TEST_F(PolaritySwitchTest, settle_not_a_multiple_of_the_period_rounds_up) {
  start({.settle = 2500us});
  run(3, false, false, {.positive = false, .gen_on = false, .switching = true});  // 2 ms < 2.5 ms
  run(1, false, true, {.positive = false, .gen_on = true, .switching = false});   // cycle 3
  run(3, true, true, {.positive = false, .gen_on = false, .switching = true});    // 4, 5, 6
  run(3, true, true, {.positive = true, .gen_on = false, .switching = true});     // 7 = 4 + 3
  run(1, true, true, {.positive = true, .gen_on = true, .switching = false});     // 10
}

TEST_F(PolaritySwitchTest, generator_already_off_long_enough_switches_at_once) {
  start({.settle = 20ms});
  run(20, false, false, {.positive = false, .gen_on = false, .switching = true});
  run(80, false, false, {.positive = false, .gen_on = false, .switching = false});
  // The generator was off (not requested) since cycle 0: the switch needs no
  // first wait.
  Out o = step(true, false);
  EXPECT_TRUE(o.positive);
  EXPECT_FALSE(o.gen_on);
  EXPECT_TRUE(o.switching);
  // But the generator waits a full settle after the switch (cycles 100..119).
  run(19, true, true, {.positive = true, .gen_on = false, .switching = true});
  run(1, true, true, {.positive = true, .gen_on = true, .switching = false});
}

TEST_F(PolaritySwitchTest, generator_off_for_part_of_settle_counts) {
  start({.settle = 20ms});
  run(20, false, true, {.positive = false, .gen_on = false, .switching = true});
  run(20, false, true, {.positive = false, .gen_on = true, .switching = false});   // 20..39
  run(8, false, false, {.positive = false, .gen_on = false, .switching = false});  // 40..47
  // Off since cycle 40: the switch comes at cycle 60, 12 cycles after the
  // request at 48.
  run(12, true, false, {.positive = false, .gen_on = false, .switching = true});  // 48..59
  run(1, true, false, {.positive = true, .gen_on = false, .switching = true});    // 60
}

TEST_F(PolaritySwitchTest, request_withdrawn_before_the_switch_restores_the_generator) {
  start({.settle = 20ms});
  run(20, false, true, {.positive = false, .gen_on = false, .switching = true});
  run(5, false, true, {.positive = false, .gen_on = true, .switching = false});  // 20..24
  run(10, true, true, {.positive = false, .gen_on = false, .switching = true});
  // Back to negative before the switch: nothing was switched, the generator may
  // run at once.
  run(3, false, true, {.positive = false, .gen_on = true, .switching = false});
}

TEST_F(PolaritySwitchTest, a_second_switch_waits_settle_after_the_first) {
  start({.settle = 20ms});
  run(20, false, false, {.positive = false, .gen_on = false, .switching = true});
  run(80, false, false, {.positive = false, .gen_on = false, .switching = false});
  ASSERT_TRUE(step(true, false).positive);  // cycle 100: immediate switch (off for long)
  // Cycle 101: negative again. The generator has been off for long, but the
  // relay has just moved: the next switch waits until cycle 120.
  run(19, false, false, {.positive = true, .gen_on = false, .switching = true});  // 101..119
  run(1, false, false, {.positive = false, .gen_on = false, .switching = true});  // 120
  run(19, false, true, {.positive = false, .gen_on = false, .switching = true});  // 121..139
  run(1, false, true, {.positive = false, .gen_on = true, .switching = false});   // 140
}

TEST_F(PolaritySwitchTest, timing_uses_release_times_across_skipped_cycles) {
  start({.settle = 20ms});
  run(20, false, true, {.positive = false, .gen_on = false, .switching = true});
  run(10, false, true, {.positive = false, .gen_on = true, .switching = false});  // 20..29
  run(1, true, true, {.positive = false, .gen_on = false, .switching = true});    // cycle 30
  h_.set_cycle(55);  // overruns skipped cycles 31..54: 25 ms have passed since 30
  run(1, true, true, {.positive = true, .gen_on = false, .switching = true});
}

// Seeded random requests: the generator is never on within `settle` of a
// polarity change.
TEST_F(PolaritySwitchTest, random_requests_never_switch_near_a_running_generator) {
  constexpr int kSettleCycles = 7;
  start({.settle = Duration{7ms}});
  std::mt19937_64 rng(20240607);
  std::bernoulli_distribution flip_request(0.02);
  std::bernoulli_distribution flip_gen(0.05);
  bool request = false;
  bool gen_request = false;
  std::vector<Out> outs;
  std::vector<bool> requests, gen_requests;
  int switches = 0;
  for (int k = 0; k < 50'000; ++k) {
    if (flip_request(rng)) {
      request = !request;
    }
    if (flip_gen(rng)) {
      gen_request = !gen_request;
    }
    outs.push_back(step(request, gen_request));
    requests.push_back(request);
    gen_requests.push_back(gen_request);
  }
  for (std::size_t k = 0; k < outs.size(); ++k) {
    // The generator runs only when asked to and with the requested polarity.
    if (outs[k].gen_on) {
      ASSERT_TRUE(gen_requests[k]) << k;
      ASSERT_EQ(outs[k].positive, requests[k]) << k;
      ASSERT_FALSE(outs[k].switching) << k;
    }
    if (k > 0 && outs[k].positive != outs[k - 1].positive) {
      ++switches;
      // Off in the kSettleCycles cycles before the change and the kSettleCycles
      // from it on.
      for (std::size_t j = k >= kSettleCycles ? k - kSettleCycles : 0;
           j < std::min(outs.size(), k + kSettleCycles); ++j) {
        ASSERT_FALSE(outs[j].gen_on) << "switch at " << k << ", generator on at " << j;
      }
    }
  }
  EXPECT_GT(switches, 100) << "the sequence exercised the switch";
}

TEST_F(PolaritySwitchTest, validate_and_runtime_write_of_settle) {
  EXPECT_TRUE(rt::validate_params(PolaritySwitchParams{}).empty());
  EXPECT_EQ(PolaritySwitchParams{}.settle, 20ms);
  EXPECT_FALSE(PolaritySwitchParams{}.initial_positive);
  EXPECT_FALSE(rt::validate_params(PolaritySwitchParams{.settle = Duration{0}}).empty());
  EXPECT_FALSE(rt::validate_params(PolaritySwitchParams{.settle = -1ms}).empty());

  start({.settle = 20ms});
  run(20, false, false, {.positive = false, .gen_on = false, .switching = true});
  run(80, false, false, {.positive = false, .gen_on = false, .switching = false});
  const auto errs = h_.write_param("settle", rt::ParamValue::of_duration(5ms));
  ASSERT_TRUE(errs.empty()) << describe(errs);
  run(1, true, true, {.positive = true, .gen_on = false, .switching = true});  // cycle 100
  run(4, true, true, {.positive = true, .gen_on = false, .switching = true});
  run(1, true, true, {.positive = true, .gen_on = true, .switching = false});  // cycle 105
  EXPECT_FALSE(h_.write_param("settle", rt::ParamValue::of_duration(Duration{0})).empty());
}

}  // namespace
}  // namespace edm::blocks
