// What an MQTT command may write (issue 31 item 13, the MQTT side): the Sparkplug datatype and
// value checked against the parameter's type before any conversion, then the registry's write
// (the entry point every source uses). The issue's case: a listed Int64 of 2^63-1 set gap.kg to
// 9.2e18.
#include "edm/telemetry/command_gate.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "support/runtime_fixture.hpp"

namespace edm::telemetry {
namespace {

namespace sp = sparkplug;
using sp::DataType;

constexpr const char* kMachine = R"(version: 1
machine:
  name: m
  io: {driver: loopback, task: main, params: {channels: 1}}
tasks:
  - {name: main, interval: 10ms, priority: 10, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: gap, type: GapControllerP}
      - {name: dsc, type: DischargeStateCounter}
bridge: {port: 0}
)";

sp::Metric metric(const char* name, DataType type, sp::Value v) {
  sp::Metric m;
  m.name = name;
  m.type = type;
  m.value = std::move(v);
  return m;
}

class Gate : public ::testing::Test {
 protected:
  Gate() : rt_(test::build_from_text(kMachine)) {}
  CommandOutcome apply(const sp::Metric& m) {
    why_.clear();
    return gate_.apply(m, why_);
  }
  double read(const char* name) { return rt_->variables().read(name).value(); }

  std::unique_ptr<rt::Runtime> rt_;
  CommandGate gate_{rt_->variables(), true, {"p.gap.kg", "p.dsc.interval", "p.dsc.arcs_as_short"}};
  std::string why_;
};

// The issue's write: refused before any conversion, with the reason, the value unchanged.
TEST_F(Gate, Int64MaxIntoGapKgIsRefusedAndTheValueUnchanged) {
  const double kg = read("p.gap.kg");
  const auto m = metric("p.gap.kg", DataType::kInt64, std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(apply(m), CommandOutcome::kOutOfRange);
  EXPECT_NE(why_.find("'p.gap.kg' is LREAL: an Int64 of 9223372036854775807 is not exact as LREAL"),
            std::string::npos)
      << why_;
  EXPECT_EQ(read("p.gap.kg"), kg);
  // UInt64 max, and as a Double (in range of a double, not of the parameter): refused too.
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kUInt64, std::numeric_limits<std::uint64_t>::max())),
            CommandOutcome::kOutOfRange);
  EXPECT_EQ(read("p.gap.kg"), kg);
  // A sensible integer goes through the registry and is written.
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kInt64, std::int64_t{1})), CommandOutcome::kWritten)
      << why_;
  EXPECT_EQ(read("p.gap.kg"), 1.0);
  // The registry's own refusal (kg > 0) arrives as out of range, its message kept.
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kInt64, std::int64_t{-3})),
            CommandOutcome::kOutOfRange);
  EXPECT_NE(why_.find("kg"), std::string::npos) << why_;
  EXPECT_EQ(read("p.gap.kg"), 1.0);
  // Exact, but outside kg's physical range (0, 10] (blocks/param_ranges.hpp, issue 31): the
  // registry's refusal, the same one the bridge and Modbus get.
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kInt64, std::int64_t{1000})),
            CommandOutcome::kOutOfRange);
  EXPECT_EQ(read("p.gap.kg"), 1.0);
}

TEST_F(Gate, IntegersOutsideBoolOrLintAreRefused) {
  EXPECT_EQ(apply(metric("p.dsc.arcs_as_short", DataType::kInt64, std::int64_t{2})),
            CommandOutcome::kOutOfRange);
  EXPECT_NE(why_.find("does not fit BOOL (0 or 1)"), std::string::npos) << why_;
  EXPECT_EQ(apply(metric("p.dsc.arcs_as_short", DataType::kInt32, std::int64_t{-1})),
            CommandOutcome::kOutOfRange);
  EXPECT_EQ(read("p.dsc.arcs_as_short"), 1.0);
  EXPECT_EQ(apply(metric("p.dsc.arcs_as_short", DataType::kUInt8, std::uint64_t{0})),
            CommandOutcome::kWritten);
  EXPECT_EQ(read("p.dsc.arcs_as_short"), 0.0);
  EXPECT_EQ(apply(metric("p.dsc.arcs_as_short", DataType::kDouble, 1.0)),
            CommandOutcome::kOutOfRange);  // a BOOL takes a Boolean or an integer 0/1

  const double interval = read("p.dsc.interval");
  EXPECT_EQ(
      apply(metric("p.dsc.interval", DataType::kUInt64, std::numeric_limits<std::uint64_t>::max())),
      CommandOutcome::kOutOfRange);
  EXPECT_NE(why_.find("does not fit LINT"), std::string::npos) << why_;
  EXPECT_EQ(apply(metric("p.dsc.interval", DataType::kDouble, 40.5)), CommandOutcome::kOutOfRange);
  EXPECT_EQ(apply(metric("p.dsc.interval", DataType::kBoolean, true)), CommandOutcome::kOutOfRange);
  // In LINT, out of the parameter's range [1, 2^30]: the registry refuses it.
  EXPECT_EQ(apply(metric("p.dsc.interval", DataType::kInt64, std::int64_t{1} << 40)),
            CommandOutcome::kOutOfRange);
  EXPECT_EQ(read("p.dsc.interval"), interval);
  EXPECT_EQ(apply(metric("p.dsc.interval", DataType::kInt16, std::int64_t{64})),
            CommandOutcome::kWritten);
  EXPECT_EQ(read("p.dsc.interval"), 64.0);
}

TEST_F(Gate, AValueThatDoesNotMatchItsDatatypeIsRefused) {
  auto m = metric("p.gap.kg", DataType::kInt8, std::int64_t{44});
  m.value_ok = false;  // e.g. an Int8 sent as 300
  EXPECT_EQ(apply(m), CommandOutcome::kOutOfRange);
  EXPECT_NE(why_.find("does not match its datatype Int8"), std::string::npos) << why_;
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kString, std::string("1e9"))),
            CommandOutcome::kOutOfRange);
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kDouble, sp::Value{})), CommandOutcome::kOutOfRange);
  EXPECT_EQ(apply(metric("p.gap.kg", DataType::kDouble, std::numeric_limits<double>::infinity())),
            CommandOutcome::kOutOfRange);
}

TEST_F(Gate, OffOrUnlistedIsRefusedAndTheNameQuoted) {
  EXPECT_EQ(apply(metric("p.gap.ki\nforged", DataType::kDouble, 0.1)), CommandOutcome::kRefused);
  EXPECT_EQ(why_, "\"p.gap.ki\\x0aforged\" is not in mqtt.commands.writable");
  CommandGate off(rt_->variables(), false, {"p.gap.kg"});
  std::string why;
  EXPECT_EQ(off.apply(metric("p.gap.kg", DataType::kDouble, 0.1), why), CommandOutcome::kRefused);
  EXPECT_EQ(why, "commands are off (mqtt.commands.enabled: false)");
}

TEST(CommandValue, TimeTakesSecondsAndIntegersAreExactOnly) {
  std::string why;
  const auto t = command_value(metric("t", DataType::kDouble, 1.5), rt::ParamType::kDuration, why);
  ASSERT_TRUE(t) << why;
  EXPECT_EQ(t->i, 1'500'000'000);
  EXPECT_FALSE(command_value(metric("t", DataType::kDouble, -1.0), rt::ParamType::kDuration, why));
  EXPECT_FALSE(command_value(metric("t", DataType::kInt64, std::int64_t{10'000'000'000}),
                             rt::ParamType::kDuration, why));
  const std::int64_t exact = std::int64_t{1} << 53;
  EXPECT_TRUE(command_value(metric("x", DataType::kInt64, exact), rt::ParamType::kReal, why));
  EXPECT_TRUE(command_value(metric("x", DataType::kInt64, -exact), rt::ParamType::kReal, why));
  EXPECT_FALSE(command_value(metric("x", DataType::kInt64, exact + 1), rt::ParamType::kReal, why));
  EXPECT_FALSE(
      command_value(metric("x", DataType::kInt64, std::numeric_limits<std::int64_t>::min()),
                    rt::ParamType::kReal, why));
  const auto lint_min =
      command_value(metric("x", DataType::kInt64, std::numeric_limits<std::int64_t>::min()),
                    rt::ParamType::kInt, why);
  ASSERT_TRUE(lint_min);
  EXPECT_EQ(lint_min->i, std::numeric_limits<std::int64_t>::min());
}

}  // namespace
}  // namespace edm::telemetry
