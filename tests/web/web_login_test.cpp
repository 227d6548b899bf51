// The log-in throttle per browser address (hmi/include/edm/hmi/web_login.hpp, issue 31 item 5),
// on explicit times: one address's failures delay that address only, 250 ms·2^(n−1) up to 10 s,
// forgotten after 60 s, one check at a time per address, a bounded table.
#include "edm/hmi/web_login.hpp"

#include <gtest/gtest.h>

#include <string>

namespace edm::hmi::test {
namespace {

using namespace std::chrono_literals;
using Clock = LoginThrottle::Clock;

/// One failed log-in from `a` at `t` (admitted, checked, refused); returns the delay.
std::chrono::milliseconds fail(LoginThrottle& th, const std::string& a, Clock::time_point t) {
  EXPECT_LE(*th.admit_at(a, t), t);
  th.begin(a);
  return th.on_failure(a, t);
}

TEST(WebLoginThrottle, delay_doubles_to_ten_seconds_for_that_address_only) {
  LoginThrottle th;
  auto t = Clock::time_point{} + 1h;
  std::chrono::milliseconds expected = 250ms;
  for (int n = 1; n <= 12; ++n) {
    const auto d = fail(th, "127.0.0.2", t);
    EXPECT_EQ(d, std::min<std::chrono::milliseconds>(expected, 10s)) << n;
    EXPECT_EQ(*th.admit_at("127.0.0.2", t), t + d);
    // Another browser is not delayed at all.
    EXPECT_EQ(*th.admit_at("127.0.0.3", t), t);
    t += d;
    expected *= 2;
  }
  EXPECT_EQ(th.failures(), 12u);
}

TEST(WebLoginThrottle, one_check_at_a_time_per_address) {
  LoginThrottle th;
  const auto t = Clock::time_point{} + 1h;
  th.begin("a");
  EXPECT_FALSE(th.admit_at("a", t)) << "40 sockets of one address: one is checked, the rest wait";
  EXPECT_EQ(*th.admit_at("b", t), t);
  th.on_abandon("a");  // edmplc did not answer: nothing learnt
  EXPECT_EQ(*th.admit_at("a", t), t);
  th.begin("a");
  th.on_success("a");
  EXPECT_EQ(*th.admit_at("a", t), t);
}

TEST(WebLoginThrottle, success_keeps_the_failures_and_sixty_seconds_forget_them) {
  LoginThrottle th;
  auto t = Clock::time_point{} + 1h;
  fail(th, "a", t);
  t += 250ms;
  fail(th, "a", t);  // 500 ms now
  th.begin("a");
  th.on_success("a");  // a viewer's right token does not reset the operator guesser's throttle
  EXPECT_EQ(*th.admit_at("a", t), t + 500ms);
  EXPECT_EQ(fail(th, "a", t + 500ms), 1000ms);
  t += 500ms + LoginThrottle::kForgetAfter + 1ms;
  EXPECT_EQ(*th.admit_at("a", t), t);
  EXPECT_EQ(fail(th, "a", t), 250ms);
}

TEST(WebLoginThrottle, the_table_is_bounded) {
  LoginThrottle th(8);
  auto t = Clock::time_point{} + 1h;
  for (int i = 0; i < 100; ++i) {
    fail(th, "10.0.0." + std::to_string(i), t);
    t += 1ms;
  }
  EXPECT_LE(th.addresses(), 8u);
  EXPECT_GT(*th.admit_at("10.0.0.99", t), t) << "the newest is remembered";
}

}  // namespace
}  // namespace edm::hmi::test
