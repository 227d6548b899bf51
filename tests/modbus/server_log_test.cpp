// What the Modbus server writes to the log about its clients (docs/modbus.md "Connections",
// docs/security.md, issue 31): lines about one peer address rate-limited (log_burst, log_per_s)
// and summed up, other addresses unaffected, frame bytes only as hex, so no client can forge a
// line or flood the log.

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <sstream>

#include "modbus/raw_client.hpp"
#include "modbus/server_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

// Every line the default logger writes while it lives, message only.
class CapturedLog {
 public:
  CapturedLog() : sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(out_)) {
    sink_->set_pattern("%v");
    spdlog::default_logger()->sinks().push_back(sink_);
  }
  ~CapturedLog() {
    auto& sinks = spdlog::default_logger()->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
  }
  std::vector<std::string> lines() {
    spdlog::default_logger()->flush();
    std::vector<std::string> v;
    std::istringstream in(out_.str());
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  }
  std::size_t count(const std::string& part) {
    const auto l = lines();
    return static_cast<std::size_t>(std::count_if(l.begin(), l.end(), [&](const std::string& x) {
      return x.find(part) != std::string::npos;
    }));
  }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
};

TEST(ModbusServerLog, LinesAboutOnePeerAreRateLimitedSummedUpAndNeverForged) {
  ServerFixture s("  log_burst: 5\n  log_per_s: 1\n");
  {
    CapturedLog log;  // after the runtime is built: every line is the server's
    const auto t0 = std::chrono::steady_clock::now();
    RawClient a(s.port(), "127.0.0.1");
    for (int i = 0; i < 200; ++i) {  // 200 refused writes (tau 0): 200 exceptions, few lines
      ASSERT_TRUE(a.send(mb_frame({6, 0, 3, 0, 0})));
      ASSERT_EQ(a.reply().size(), 9U);
    }
    const double took_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::size_t from_a = log.count("127.0.0.1:");
    EXPECT_GE(from_a, 5U);
    EXPECT_LE(static_cast<double>(from_a), 5.0 + took_s * 1.0 + 1.0) << took_s;
    EXPECT_GE(static_cast<double>(s.counters().log_suppressed), 200.0 - 5.0 - took_s - 1.0);
    // Another address has its own budget.
    RawClient b(s.port(), "127.0.0.2");
    ASSERT_TRUE(b.send(mb_frame({6, 0, 3, 0, 0})));
    ASSERT_EQ(b.reply().size(), 9U);
    EXPECT_EQ(log.count("127.0.0.2:"), 1U);
    // A's next line, once its budget refills, says how many were dropped.
    EXPECT_TRUE(ServerFixture::eventually(
        [&] {
          EXPECT_TRUE(a.send(mb_frame({6, 0, 3, 0, 0})));
          EXPECT_EQ(a.reply().size(), 9U);
          return log.count("earlier lines from this peer suppressed") == 1U;
        },
        4s));
    // A write of two values refused at the second: the first is written, the line says both.
    RawClient d(s.port(), "127.0.0.4");
    ASSERT_TRUE(d.send(mb_frame({16, 0, 3, 0, 3, 6, 0, 20, 0x7F, 0xC0, 0, 0})));  // tau, k = NaN
    const Bytes r = d.reply();
    ASSERT_EQ(r.size(), 9U);
    EXPECT_EQ(r[8], 3);
    EXPECT_EQ(log.count("127.0.0.4:"), 1U);
    EXPECT_EQ(log.count("wrote p.lp.tau = 0.02; write p.g.k = nan refused: \"'p.g.k':"), 1U)
        << log.lines().back();
    // A frame of newlines and escape bytes: logged as hex, no line of its own.
    RawClient c(s.port(), "127.0.0.3");
    ASSERT_TRUE(c.send({'\n', '\r', 0x0A, 0x1B, '\n', '\n', 'X', '\n'}));
    EXPECT_TRUE(c.closed_within(2s));
    EXPECT_TRUE(ServerFixture::eventually([&] { return log.count("0a 0d 0a 1b 0a 0a 58") == 1; }));
    // 200 peers, one bad frame each: every address may log, all of them together 10x one.
    const auto t1 = std::chrono::steady_clock::now();
    for (int i = 0; i < 200; ++i) {
      RawClient e(s.port(), "127.0.2." + std::to_string(i + 1));
      ASSERT_TRUE(e.send({0, 1, 0, 7, 0, 6, 1}));
      ASSERT_TRUE(e.closed_within(2s));
    }
    const double t_all =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    const std::size_t bad = log.count("127.0.2.");
    EXPECT_GE(bad, 30U);  // the total's burst (50), less what the lines above took
    EXPECT_LE(static_cast<double>(bad), 50.0 + 10.0 * t_all + 1.0) << t_all;
    for (const std::string& l : log.lines()) {
      EXPECT_EQ(l.rfind("modbus_server: ", 0), 0U) << l;
    }
  }
}

}  // namespace
}  // namespace edm::test
