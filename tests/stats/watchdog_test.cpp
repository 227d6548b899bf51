#include "edm/runtime/watchdog.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <limits>

namespace edm::rt {
namespace {

using std::chrono::microseconds;
constexpr auto kOk = WatchdogVerdict::kOk;
constexpr auto kTrip = WatchdogVerdict::kTrip;

WatchdogSpec spec(Duration time, int sensitivity, bool enabled = true) {
  WatchdogSpec s;
  s.enabled = enabled;
  s.time = time;
  s.sensitivity = sensitivity;
  return s;
}

// Three 150 µs cycles on a 100 µs, sensitivity-3 watchdog whose count is 0: the third trips.
void expect_third_overrun_trips(Watchdog& w) {
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.check(microseconds(150)), kTrip);
}

TEST(Watchdog, sensitivity_one_trips_on_first_overrun) {
  Watchdog w(spec(microseconds(100), 1));
  EXPECT_EQ(w.check(microseconds(50)), kOk);
  EXPECT_EQ(w.check(microseconds(101)), kTrip);
  EXPECT_EQ(w.consecutive(), 0);
  EXPECT_EQ(w.check(microseconds(100)), kOk);
}

TEST(Watchdog, sensitivity_three_trips_on_exactly_the_third_consecutive_overrun) {
  Watchdog w(spec(microseconds(100), 3));
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.consecutive(), 1);
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.consecutive(), 2);
  EXPECT_EQ(w.check(microseconds(150)), kTrip);
  // The count restarts: a continuing overload trips again every third cycle.
  EXPECT_EQ(w.consecutive(), 0);
  expect_third_overrun_trips(w);
}

TEST(Watchdog, single_cycle_over_time_times_sensitivity_trips_at_once) {
  Watchdog w(spec(microseconds(100), 3));
  EXPECT_EQ(w.check(microseconds(300)), kOk);  // equal to time * sensitivity: not over it
  EXPECT_EQ(w.check(microseconds(50)), kOk);
  EXPECT_EQ(w.check(microseconds(301)), kTrip);
  EXPECT_EQ(w.consecutive(), 0);
}

TEST(Watchdog, in_time_cycle_resets_the_count) {
  Watchdog w(spec(microseconds(100), 3));
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.check(microseconds(99)), kOk);
  EXPECT_EQ(w.consecutive(), 0);
  expect_third_overrun_trips(w);
}

TEST(Watchdog, exactly_time_is_in_time) {
  Watchdog w(spec(microseconds(100), 2));
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(w.check(microseconds(100)), kOk);
  }
  EXPECT_EQ(w.check(microseconds(100) + Duration(1)), kOk);
  EXPECT_EQ(w.consecutive(), 1);
  EXPECT_EQ(w.check(microseconds(100)), kOk);  // resets
  EXPECT_EQ(w.consecutive(), 0);
}

TEST(Watchdog, disabled_never_trips) {
  Watchdog w(spec(microseconds(100), 1, /*enabled=*/false));
  EXPECT_FALSE(w.enabled());
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(w.check(std::chrono::seconds(10)), kOk);
  }
  EXPECT_EQ(w.consecutive(), 0);
}

TEST(Watchdog, huge_time_times_sensitivity_does_not_wrap) {
  Watchdog w(spec(Duration(std::numeric_limits<Duration::rep>::max() / 2), 5));
  EXPECT_EQ(w.check(Duration(std::numeric_limits<Duration::rep>::max() / 2 + 1)), kOk);
  EXPECT_EQ(w.consecutive(), 1);
}

TEST(Watchdog, reset_clears_the_count) {
  Watchdog w(spec(microseconds(100), 3));
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  w.reset();
  EXPECT_EQ(w.check(microseconds(150)), kOk);
  EXPECT_EQ(w.consecutive(), 1);
}

}  // namespace
}  // namespace edm::rt
