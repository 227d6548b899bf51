// The one escaping of untrusted text for logs and the audit file, and the per-peer log rate
// limit (issue 31, item 8): runtime/include/edm/runtime/log_escape.hpp, log_limiter.hpp.
#include "edm/runtime/log_escape.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "edm/runtime/log_limiter.hpp"

namespace edm::rt {
namespace {

using namespace std::chrono_literals;

// Decodes log_quote's output back to the bytes it shows (the test's own inverse).
std::string unquote(const std::string& q, char quote = '"') {
  std::string out;
  EXPECT_GE(q.size(), 2u);
  EXPECT_EQ(q.front(), quote);
  std::size_t end = q.rfind(quote);
  for (std::size_t i = 1; i < end; ++i) {
    if (q[i] != '\\') {
      out.push_back(q[i]);
    } else if (q[i + 1] == 'x') {
      out.push_back(static_cast<char>(std::stoi(q.substr(i + 2, 2), nullptr, 16)));
      i += 3;
    } else {
      out.push_back(q[++i]);
    }
  }
  return out;
}

TEST(LogEscape, every_byte_is_printable_ascii_and_round_trips) {
  std::string all;
  for (int c = 0; c < 256; ++c) all.push_back(static_cast<char>(c));
  const std::string q = log_quote(all, all.size());
  // Nothing a terminal or a line-based reader would act on: no control byte, no newline, no
  // byte above 0x7e, and the only unescaped quotes are the two around it.
  EXPECT_TRUE(is_printable_ascii(q)) << q;
  EXPECT_EQ(q.find('\n'), std::string::npos);
  EXPECT_EQ(unquote(q), all);
  EXPECT_EQ(log_quote("a\nb"), "\"a\\x0ab\"");
  EXPECT_EQ(log_quote("say \"hi\"\\"), "\"say \\\"hi\\\"\\\\\"");
  EXPECT_EQ(log_quote("\xc3\xa9t\xc3\xa9"), "\"\\xc3\\xa9t\\xc3\\xa9\"");  // "été", as bytes
  EXPECT_EQ(log_quote("it's", 64, '\''), "'it\\'s'");
  EXPECT_EQ(log_quote(""), "\"\"");
}

TEST(LogEscape, long_text_is_cut_with_a_mark_no_input_can_imitate) {
  const std::string long_name(1'000'000, 'a');
  const std::string q = log_quote(long_name);
  EXPECT_EQ(q, "\"" + std::string(kLogQuoteMaxBytes, 'a') + "\"\xe2\x80\xa6");
  // A name of exactly the limit is not marked; one that ends in "…" itself shows it escaped.
  EXPECT_EQ(log_quote(std::string(64, 'b')), "\"" + std::string(64, 'b') + "\"");
  EXPECT_EQ(log_quote("x\xe2\x80\xa6"), "\"x\\xe2\\x80\\xa6\"");
}

TEST(LogEscape, seeded_random_names_never_leave_their_quotes) {
  std::mt19937 rng(31);
  for (int n = 0; n < 2000; ++n) {
    std::string s(rng() % 200, '\0');
    for (char& c : s) c = static_cast<char>(rng() % 256);
    std::string q = log_quote(s);
    if (s.size() > kLogQuoteMaxBytes) {  // the cut mark, the one non-ASCII text, after the quote
      ASSERT_EQ(q.substr(q.size() - 3), "\xe2\x80\xa6");
      q.resize(q.size() - 3);
    }
    EXPECT_TRUE(is_printable_ascii(q)) << q;
    EXPECT_EQ(unquote(q), s.substr(0, kLogQuoteMaxBytes));
    EXPECT_EQ(unquote(log_quote(s, s.size())), s);
  }
}

TEST(LogEscape, the_fmt_formatter_is_the_same_escaping) {
  EXPECT_EQ(fmt::format("name={}", log_quoted("a\r\nop=estop")), "name=\"a\\x0d\\x0aop=estop\"");
  EXPECT_EQ(fmt::format("{}", log_quoted(std::string(70, 'z'))), log_quote(std::string(70, 'z')));
}

TEST(LogRateLimiterUnit, a_burst_then_the_rate_and_the_suppressed_count_is_reported_once) {
  LogRateLimiter lim({.burst = 5, .per_s = 2.0, .max_keys = 8});
  const auto t0 = LogRateLimiter::Clock::time_point{} + 1h;
  std::uint64_t n = 0;
  int logged = 0;
  for (int i = 0; i < 1000; ++i) logged += lim.admit("10.0.0.1", t0, n) ? 1 : 0;
  EXPECT_EQ(logged, 5) << "the burst, then nothing at the same instant";
  EXPECT_EQ(lim.suppressed_total(), 995u);
  // Another peer is not affected.
  EXPECT_TRUE(lim.admit("10.0.0.2", t0, n));
  EXPECT_EQ(n, 0u);
  // Half a second later one token is back: the next line says how many were suppressed.
  EXPECT_TRUE(lim.admit("10.0.0.1", t0 + 500ms, n));
  EXPECT_EQ(n, 995u);
  EXPECT_TRUE(lim.admit("10.0.0.1", t0 + 1000ms, n));
  EXPECT_EQ(n, 0u) << "reported once";
  // Over 10 s of flooding, about burst + 10 s × 2/s lines.
  int in_10s = 0;
  for (int ms = 0; ms < 10'000; ++ms) {
    in_10s += lim.admit("10.0.0.3", t0 + std::chrono::milliseconds(ms), n) ? 1 : 0;
  }
  EXPECT_GE(in_10s, 5 + 19);
  EXPECT_LE(in_10s, 5 + 21);
}

TEST(LogRateLimiterUnit, sweep_sums_up_a_flood_that_stopped_and_keys_are_bounded) {
  LogRateLimiter lim({.burst = 2, .per_s = 1.0, .max_keys = 4});
  const auto t0 = LogRateLimiter::Clock::time_point{} + 1h;
  std::uint64_t n = 0;
  for (int i = 0; i < 50; ++i) lim.admit("p", t0, n);
  std::vector<std::pair<std::string, std::uint64_t>> seen;
  const auto collect = [&](const std::string& k, std::uint64_t c) { seen.emplace_back(k, c); };
  lim.sweep(t0 + 1s, 5s, collect);
  EXPECT_TRUE(seen.empty()) << "not quiet long enough";
  lim.sweep(t0 + 6s, 5s, collect);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], (std::pair<std::string, std::uint64_t>{"p", 48}));
  lim.sweep(t0 + 20s, 5s, collect);
  EXPECT_EQ(seen.size(), 1u) << "once";
  for (int k = 0; k < 100; ++k) lim.admit("peer" + std::to_string(k), t0, n);
  EXPECT_EQ(lim.suppressed_total(), 48u) << "new keys start with a full bucket";
}

TEST(LogRateLimiterUnit, suppressed_note_is_empty_for_zero) {
  EXPECT_EQ(suppressed_note(0), "");
  EXPECT_EQ(suppressed_note(1), " (1 earlier line from this peer suppressed)");
  EXPECT_EQ(suppressed_note(7), " (7 earlier lines from this peer suppressed)");
}

}  // namespace
}  // namespace edm::rt
