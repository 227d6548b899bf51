// The edge node's command intake against hostile input, without a broker (issue 31 items 11,
// 12 and the attacker's pass): forged log lines, huge names, payloads and metric counts, floods,
// repeated metrics, aliases, retained and foreign messages, malformed protobuf, rebirth spoofs.
#include "edm/telemetry/command_intake.hpp"

#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "payloads.hpp"

namespace edm::telemetry {
namespace {

using namespace sparkplug::test;  // payloads.hpp
using sparkplug::InboundLimits;
using sparkplug::kRebirth;
using sparkplug::MessageType;
using sparkplug::Metric;

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr const char* kNcmd = "spBv1.0/g/NCMD/n";
constexpr const char* kDcmd = "spBv1.0/g/DCMD/n/d";

class Intake : public ::testing::Test {
 protected:
  // `handler`: empty means commands off (every metric refused).
  void make(CommandHandler handler = {}, InboundLimits limits = {}) {
    IntakeOptions o;
    o.ncmd_topic = kNcmd;
    o.dcmd_topic = kDcmd;
    o.broker = "127.0.0.1:1883";
    o.limits = limits;
    o.info = [this](const std::string& l) { lines_.push_back("info " + l); };
    o.warn = [this](const std::string& l) { lines_.push_back("warn " + l); };
    intake_ = std::make_unique<CommandIntake>(std::move(o), std::move(handler));
  }
  bool process(Clock::duration at = 0s) { return intake_->process(t0_ + at); }
  [[nodiscard]] std::size_t count(const std::string& text) const {
    std::size_t n = 0;
    for (const auto& l : lines_) n += l.find(text) != std::string::npos ? 1 : 0;
    return n;
  }
  void expect_one_line_each() const {
    for (const auto& l : lines_) {
      EXPECT_EQ(l.find_first_of("\n\r"), std::string::npos) << l;
      EXPECT_LE(l.size(), 700u) << l.substr(0, 200);
    }
  }

  std::unique_ptr<CommandIntake> intake_;
  std::vector<std::string> lines_;
  Clock::time_point t0_{};
};

// Item 11, commands off (the default): the name is quoted and escaped, the forged line is not.
TEST_F(Intake, ANewlineInANameForgesNoLineWithCommandsOff) {
  make();
  const std::string forged =
      "p.level.k\n[2025-01-01 00:00:00.000] [info] mqtt audit: DCMD \"cnc.estop\"=1 (Boolean) "
      "from broker 127.0.0.1:1883: written";
  intake_->offer(kDcmd, double_metric(forged, 3.0), false);
  process();
  ASSERT_EQ(lines_.size(), 1u);
  expect_one_line_each();
  EXPECT_EQ(count("refused: commands are off"), 1u);
  EXPECT_EQ(count("\"p.level.k\\x0a[2025"), 1u) << lines_[0];
  EXPECT_EQ(intake_->refused(), 1u);
}

// Item 11: a long name makes a short line (a 60 KB name, under the 64 KiB payload limit).
TEST_F(Intake, ALongNameIsCappedInTheLog) {
  make();
  intake_->offer(kDcmd, double_metric(std::string(60000, 'n'), 1.0), false);
  intake_->offer(
      kDcmd,
      one_metric("s", pb::String,
                 [](pb::Payload::Metric& m) { m.set_string_value(std::string(60000, '\n')); }),
      false);
  process();
  ASSERT_EQ(lines_.size(), 2u);
  expect_one_line_each();
  EXPECT_EQ(count("nnnn\"\xe2\x80\xa6="), 1u);                // the name, cut
  EXPECT_EQ(count("\\x0a\\x0a\"\xe2\x80\xa6 (String)"), 1u);  // the value, cut
}

// Item 11: repeated lines are rate-limited per episode, counted, and summed up once.
TEST_F(Intake, AFloodOfRefusedCommandsIsABurstAndOneSummary) {
  make();
  for (int i = 0; i < 1000; ++i) {
    intake_->offer(kDcmd, double_metric("p.level.k", i), false);
    if (i % 100 == 99) process(1ms * i);
  }
  EXPECT_EQ(lines_.size(), 20u);  // the audit's burst (then one per 2 s)
  EXPECT_EQ(intake_->refused(), 1000u);
  process(11s);  // quiet for 10 s: one line with the count
  ASSERT_EQ(lines_.size(), 21u);
  EXPECT_EQ(count("mqtt audit: 980 more command lines (refused) not logged one by one; "
                  "Commands/accepted 0, Commands/refused 1000"),
            1u)
      << lines_.back();
  expect_one_line_each();
}

// Item 12: 30 payloads of 8 MB and a 100k-metric DCMD: one line each kind, counted, never
// copied into the inbox, never decoded, never handed to the handler.
TEST_F(Intake, HugePayloadsAndMetricCountsAreDroppedUnreadOncePerEpisode) {
  int handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kWritten;
  });
  const std::string big(8 << 20, 'x');
  for (int i = 0; i < 30; ++i) {
    intake_->offer(kDcmd, big, false);
    if (i % 3 == 2) process(100ms * i);
  }
  pb::Payload p;
  for (int i = 0; i < 100000; ++i) add_metric(p, "p.level.k", pb::Double)->set_double_value(i);
  intake_->offer(kDcmd, p.SerializeAsString(), false);  // 2.4 MB: too large first
  process(4s);
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(intake_->dropped(), 31u);
  EXPECT_EQ(lines_.size(), 1u);
  EXPECT_EQ(count("warn mqtt: dropped a DCMD of 8388608 bytes unread: over "
                  "mqtt.limits.max_payload_bytes (65536); 2 more like it not logged one by one; "
                  "Commands/dropped 3 (told at most once per 10 s)"),
            1u)
      << lines_[0];
  process(30s);  // quiet: the rest summed up once
  ASSERT_EQ(lines_.size(), 2u);
  EXPECT_EQ(count("mqtt: 28 more NCMD/DCMD over mqtt.limits.max_payload_bytes dropped unread"), 1u)
      << lines_[1];
  // Under a payload limit that lets it in, the metric count stops it.
  lines_.clear();
  InboundLimits roomy;
  roomy.max_payload_bytes = 16 << 20;
  make(
      [&](MessageType, const Metric&, std::string&) {
        ++handled;
        return CommandOutcome::kWritten;
      },
      roomy);
  for (int i = 0; i < 3; ++i) intake_->offer(kDcmd, p.SerializeAsString(), false);
  process();
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(intake_->dropped(), 3u);
  ASSERT_EQ(lines_.size(), 1u);
  EXPECT_EQ(count("dropped a DCMD of 100000 metrics unread: over mqtt.limits.max_metrics (256)"),
            1u);
  intake_->finish(t0_ + 1s);
  EXPECT_EQ(count("2 more NCMD/DCMD over mqtt.limits.max_metrics dropped unread"), 1u);
}

// Item 12: the inbox is bounded in messages and bytes, whatever arrives between two ticks.
TEST_F(Intake, TheInboxIsBoundedInBytesAndMessages) {
  std::size_t handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kRefused;
  });
  const std::string near_limit = double_metric(std::string(65000, 'n'), 1.0);
  for (int i = 0; i < 100; ++i) intake_->offer(kDcmd, near_limit, false);
  for (int i = 0; i < 1000; ++i) intake_->offer(kDcmd, double_metric("x", 1.0), false);
  process();
  const std::size_t fit = intake_->inbox_byte_capacity() / near_limit.size();
  EXPECT_LE(handled, CommandIntake::kInboxMessages);
  EXPECT_GE(handled, fit);
  EXPECT_EQ(intake_->dropped(), 1100u - handled);
  EXPECT_EQ(count("the inbox is full"), 1u);
}

// Item 12: the network thread only offers; decoding and the handler run on the owner's thread.
TEST_F(Intake, DecodingAndTheHandlerRunOnTheOwnersThreadOnly) {
  std::vector<std::thread::id> seen;
  make([&](MessageType, const Metric&, std::string&) {
    seen.push_back(std::this_thread::get_id());
    return CommandOutcome::kWritten;
  });
  std::thread network([&] {
    for (int i = 0; i < 200; ++i) intake_->offer(kDcmd, double_metric("p.level.k", i), false);
  });
  network.join();
  process();
  ASSERT_EQ(seen.size(), 200u);
  for (const auto& id : seen) EXPECT_EQ(id, std::this_thread::get_id());
  EXPECT_EQ(intake_->accepted(), 200u);
}

TEST_F(Intake, MalformedProtobufIsDroppedAndToldOncePerEpisode) {
  make();
  for (int i = 0; i < 50; ++i) intake_->offer(kDcmd, std::string("\x0A\xFF\xFF", 3), false);
  intake_->offer(kNcmd, std::string(10, '\xFF'), false);
  process();
  EXPECT_EQ(intake_->dropped(), 51u);
  EXPECT_EQ(lines_.size(), 1u);
  EXPECT_EQ(count("not a Sparkplug B payload"), 1u);
}

TEST_F(Intake, ARepeatedMetricRefusesTheWholeMessage) {
  int handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kWritten;
  });
  pb::Payload p;
  add_metric(p, "p.level.k", pb::Double)->set_double_value(1.0);
  add_metric(p, "p.level.offset", pb::Double)->set_double_value(1.0);
  add_metric(p, "p.level.k", pb::Double)->set_double_value(1e9);
  intake_->offer(kDcmd, p.SerializeAsString(), false);
  process();
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(intake_->refused(), 3u);
  EXPECT_EQ(count("the metric \"p.level.k\" appears more than once"), 1u);
}

TEST_F(Intake, AnAliasWithoutANameIsRefused) {
  int handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kWritten;
  });
  intake_->offer(kDcmd,
                 one_metric("", pb::Double,
                            [](pb::Payload::Metric& m) {
                              m.set_alias(12345);
                              m.set_double_value(2.0);
                            }),
                 false);
  process();
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(count("a metric by alias 12345 only: edmplc defines no aliases"), 1u);
}

// Messages edmplc must not act on: a retained command (replayed at every connect), a topic that
// is not exactly this node's (another node, a wildcard, a huge name), an NBIRTH sent to it.
TEST_F(Intake, RetainedAndForeignMessagesAreDropped) {
  int handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kWritten;
  });
  const std::string cmd = double_metric("p.level.k", 3.0);
  intake_->offer(kDcmd, cmd, true);
  intake_->offer("spBv1.0/g/DCMD/n/other", cmd, false);
  intake_->offer("spBv1.0/g/NBIRTH/n", cmd, false);
  intake_->offer("spBv1.0/g/DCMD/n/#", cmd, false);
  intake_->offer("spBv1.0/g/DCMD/n/d\n" + std::string(100000, 'x'), cmd, false);
  process();
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(intake_->dropped(), 5u);
  EXPECT_EQ(count("dropped a retained DCMD"), 1u);
  EXPECT_EQ(count("not this node's NCMD or DCMD topic"), 1u);  // one episode
  expect_one_line_each();
}

TEST_F(Intake, RebirthOnlyAsABooleanOnTheNodesNcmd) {
  int handled = 0;
  make([&](MessageType, const Metric&, std::string&) {
    ++handled;
    return CommandOutcome::kRefused;
  });
  const auto rebirth = [](auto set, std::uint32_t type) {
    return one_metric(std::string(kRebirth), type, set);
  };
  intake_->offer(kNcmd,
                 rebirth([](pb::Payload::Metric& m) { m.set_boolean_value(true); }, pb::Boolean),
                 false);
  EXPECT_TRUE(process());
  intake_->offer(kNcmd,
                 rebirth([](pb::Payload::Metric& m) { m.set_boolean_value(false); }, pb::Boolean),
                 false);
  EXPECT_FALSE(process());
  intake_->offer(
      kNcmd, rebirth([](pb::Payload::Metric& m) { m.set_double_value(1.0); }, pb::Double), false);
  intake_->offer(kNcmd, rebirth([](pb::Payload::Metric& m) { m.set_long_value(1); }, pb::Boolean),
                 false);
  EXPECT_FALSE(process());
  EXPECT_EQ(count("Node Control/Rebirth takes a Boolean"), 2u);
  EXPECT_EQ(handled, 0);
  // In a DCMD it is just a metric nobody may write.
  intake_->offer(kDcmd,
                 rebirth([](pb::Payload::Metric& m) { m.set_boolean_value(true); }, pb::Boolean),
                 false);
  EXPECT_FALSE(process());
  EXPECT_EQ(handled, 1);
}

TEST_F(Intake, TheHandlersOutcomesAreCounted) {
  make([](MessageType, const Metric& m, std::string& why) {
    why = "because";
    if (m.name == "w") return CommandOutcome::kWritten;
    return m.name == "r" ? CommandOutcome::kOutOfRange : CommandOutcome::kRefused;
  });
  pb::Payload p;
  for (const char* n : {"w", "r", "x"}) add_metric(p, n, pb::Double)->set_double_value(1.0);
  intake_->offer(kDcmd, p.SerializeAsString(), false);
  process();
  EXPECT_EQ(intake_->accepted(), 1u);
  EXPECT_EQ(intake_->refused(), 2u);
  EXPECT_EQ(intake_->out_of_range(), 1u);
  EXPECT_EQ(count("info mqtt audit: DCMD \"w\"=1 (Double) from broker 127.0.0.1:1883: written"),
            1u);
  EXPECT_EQ(count("\"r\"=1 (Double) from broker 127.0.0.1:1883: refused: because"), 1u);
}

}  // namespace
}  // namespace edm::telemetry
