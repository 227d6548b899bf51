// The screen before decoding (issue 31 item 12) and what decode() says about a metric's value
// (item 13: a datatype whose wire field or range does not match is flagged, never truncated).
#include "edm/sparkplug/inbound.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "edm/sparkplug/sparkplug.hpp"
#include "payloads.hpp"

namespace edm::sparkplug::test {
namespace {

TEST(Screen, OverTheSizeLimitIsNotLookedInto) {
  const InboundLimits lim;                 // 64 KiB, 256 metrics
  const std::string big(8 << 20, '\xFF');  // not even protobuf: never read
  const ScreenResult r = screen_payload(big, lim);
  EXPECT_EQ(r.verdict, Screen::kTooLarge);
  EXPECT_EQ(r.bytes, std::size_t{8} << 20);
  EXPECT_EQ(screen_payload(std::string(lim.max_payload_bytes, '\0'), lim).verdict,
            Screen::kMalformed);  // at the limit it is screened (field 0: malformed)
}

TEST(Screen, CountsMetricsWithoutDecoding) {
  const InboundLimits lim;
  EXPECT_EQ(screen_payload(many_metrics(256), lim).verdict, Screen::kOk);
  const ScreenResult r = screen_payload(many_metrics(257), lim);
  EXPECT_EQ(r.verdict, Screen::kTooManyMetrics);
  EXPECT_EQ(r.metrics, 257u);
  // The 100k-metric DCMD (empty metrics: 2 bytes each) under a raised size limit.
  pb::Payload p;
  for (int i = 0; i < 100000; ++i) p.add_metrics();
  InboundLimits roomy;
  roomy.max_payload_bytes = 16 << 20;
  const ScreenResult h = screen_payload(p.SerializeAsString(), roomy);
  EXPECT_EQ(h.verdict, Screen::kTooManyMetrics);
  EXPECT_EQ(h.metrics, 100000u);
  // With the default size limit it is too large first (200 kB).
  EXPECT_EQ(screen_payload(p.SerializeAsString(), lim).verdict, Screen::kTooLarge);
}

TEST(Screen, RefusesBrokenFraming) {
  const InboundLimits lim;
  const std::string good = double_metric("p.level.k", 3.0);
  ASSERT_EQ(screen_payload(good, lim).verdict, Screen::kOk);
  EXPECT_EQ(screen_payload(good.substr(0, good.size() - 1), lim).verdict, Screen::kMalformed);
  EXPECT_EQ(screen_payload(std::string(11, '\xFF'), lim).verdict, Screen::kMalformed);     // varint
  EXPECT_EQ(screen_payload(std::string("\x13\x14", 2), lim).verdict, Screen::kMalformed);  // group
  EXPECT_EQ(screen_payload(std::string("\x00\x00", 2), lim).verdict,
            Screen::kMalformed);  // field 0
  EXPECT_EQ(screen_payload(std::string("\x10\x01", 2), lim).verdict,
            Screen::kMalformed);  // metrics as varint
  EXPECT_EQ(screen_payload(std::string("\x12\xFF\xFF\xFF\xFF\x0F", 6), lim).verdict,
            Screen::kMalformed);                            // a 4 GiB length in 6 bytes
  EXPECT_EQ(screen_payload("", lim).verdict, Screen::kOk);  // an empty payload: no metrics
}

TEST(Screen, RandomBytesNeverCrashAndScreenedOnesDecodeSafely) {
  std::mt19937 rng(12);
  const InboundLimits lim;
  int ok = 0;
  for (int i = 0; i < 5000; ++i) {
    std::string s(rng() % 64, '\0');
    for (char& c : s) c = static_cast<char>(rng() % 4 == 0 ? 0x12 : rng());
    if (screen_payload(s, lim).verdict == Screen::kOk) {
      ++ok;
      (void)decode(s);  // may or may not parse; bounded by the size limit either way
    }
  }
  EXPECT_GT(ok, 0);
}

Metric decoded(const std::string& bytes) {
  const auto p = decode(bytes);
  EXPECT_TRUE(p && p->metrics.size() == 1);
  return p && !p->metrics.empty() ? p->metrics[0] : Metric{};
}

TEST(Decode, FlagsAValueOutsideItsDatatype) {
  const auto int_as = [](std::uint32_t type, std::uint32_t v) {
    return decoded(one_metric("x", type, [v](pb::Payload::Metric& m) { m.set_int_value(v); }));
  };
  EXPECT_TRUE(int_as(pb::Int8, 127).value_ok);
  const Metric minus_one = int_as(pb::Int8, 0xFFFFFFFFu);  // -1, two's complement in 32 bits
  EXPECT_TRUE(minus_one.value_ok);
  EXPECT_EQ(std::get<std::int64_t>(minus_one.value), -1);
  EXPECT_FALSE(int_as(pb::Int8, 300).value_ok);  // was silently 44
  EXPECT_FALSE(int_as(pb::Int16, 70000).value_ok);
  EXPECT_FALSE(int_as(pb::UInt8, 256).value_ok);
  EXPECT_TRUE(int_as(pb::UInt16, 65535).value_ok);
  // A value in another datatype's field.
  EXPECT_FALSE(decoded(one_metric("x", pb::Int64, [](pb::Payload::Metric& m) {
                 m.set_double_value(1.0);
               })).value_ok);
  EXPECT_FALSE(decoded(one_metric("x", pb::Boolean, [](pb::Payload::Metric& m) {
                 m.set_long_value(7);
               })).value_ok);
  EXPECT_FALSE(decoded(one_metric("x", pb::Unknown, [](pb::Payload::Metric& m) {
                 m.set_double_value(1.0);
               })).value_ok);
  EXPECT_FALSE(decoded(one_metric("x", pb::DataSet, [](pb::Payload::Metric&) {})).value_ok);
  EXPECT_FALSE(decoded(one_metric("x", pb::Double, [](pb::Payload::Metric&) {})).value_ok);
  EXPECT_TRUE(decoded(one_metric("x", pb::Double, [](pb::Payload::Metric& m) {
                m.set_is_null(true);
              })).value_ok);
  const Metric big = decoded(int64_metric("x", INT64_MAX));
  EXPECT_TRUE(big.value_ok);
  EXPECT_EQ(std::get<std::int64_t>(big.value), INT64_MAX);
}

TEST(Decode, KeepsTheAlias) {
  const Metric m = decoded(one_metric("", pb::Double, [](pb::Payload::Metric& pm) {
    pm.set_alias(7);
    pm.set_double_value(1.0);
  }));
  EXPECT_TRUE(m.name.empty());
  ASSERT_TRUE(m.alias.has_value());
  EXPECT_EQ(*m.alias, 7u);
}

}  // namespace
}  // namespace edm::sparkplug::test
