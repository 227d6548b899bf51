// Wire resolution, evaluation order, every wiring error, forcing and runtime parameter writes.

#include <gtest/gtest.h>

#include <cmath>

#include "edm/runtime/scheduler.hpp"
#include "support/files.hpp"
#include "support/runtime_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

// Programs p (these `blocks` and `wires` lines) and q on one task of a loopback machine.
std::string with_program(const std::string& blocks, const std::string& wires) {
  return test_data("runtime/two_programs.yaml", {{"blocks", blocks}, {"wires", wires}});
}

const std::string kChain =
    "      - {name: a, type: AddOne}\n"
    "      - {name: b, type: AddOne}\n";

// Steps every task once per call on a virtual clock.
struct Stepper {
  explicit Stepper(rt::Runtime& r) : rt(r) { r.machine().command(rt::MachineCommand::kPowerOn); }
  void step() {
    for (const auto& t : rt.tasks()) {
      t->run_cycle(now, clock);
    }
    now += 1ms;
    clock.advance_to(now);
  }
  double read(const std::string& n) { return rt.variables().read(n).value(); }
  rt::Runtime& rt;
  rt::VirtualClock clock;
  rt::TimePoint now{0};
};

TEST(Wiring, ForwardWireSeesThisCycleBackwardWireThePreviousOne) {
  // a.in <- b.out (backwards: b runs after a), b.in <- a.out (forwards).
  auto r = build_from_text(with_program(kChain, "      a.in: b.out\n      b.in: a.out\n"));
  Stepper s(*r);
  // cycle 0: a = 0+1 = 1 (b.out still 0), b = 1+1 = 2
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 1.0);
  EXPECT_EQ(s.read("p.b.out"), 2.0);
  // cycle 1: a = 2+1 = 3 (last cycle's b), b = 3+1 = 4
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 3.0);
  EXPECT_EQ(s.read("p.b.out"), 4.0);
}

TEST(Wiring, ConstantAndCrossProgramAndLoopback) {
  // q.b is wired from io.ai1, which returns p.a.out one cycle later through the loopback.
  std::string cfg = with_program(kChain,
                                 "      a.in: 41.5\n      b.in: q.b.out\n"
                                 "      io.ao1: a.out\n");
  cfg += "    wires:\n      b.in: io.ai1\n";
  auto r = build_from_text(cfg);
  Stepper s(*r);
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 42.5);
  EXPECT_EQ(s.read("q.b.out"), 1.0) << "ai1 is 0 in cycle 0";
  EXPECT_EQ(s.read("p.b.out"), 1.0) << "q runs after p: p.b saw q.b from before cycle 0";
  s.step();
  EXPECT_EQ(s.read("io.ai1"), 42.5);
  EXPECT_EQ(s.read("q.b.out"), 43.5);
  EXPECT_EQ(s.read("p.b.out"), 2.0);
}

struct WireError {
  const char* name;
  const char* wires;
  int line;
  int col;
  const char* message;
};

class WiringErrors : public ::testing::TestWithParam<WireError> {};

TEST_P(WiringErrors, AreReportedAtTheWireWithTheProblemNamed) {
  const WireError& e = GetParam();
  const rt::Diagnostic d = build_error(with_program(kChain, e.wires));
  EXPECT_EQ(d.loc.file, "test.yaml");
  EXPECT_EQ(d.loc.line, e.line);
  EXPECT_EQ(d.loc.col, e.col);
  EXPECT_NE(d.message.find(e.message), std::string::npos) << d.str();
}

// With two blocks, the first wire is on line 13 of with_program(), indented by 6.
INSTANTIATE_TEST_SUITE_P(
    All, WiringErrors,
    ::testing::Values(
        WireError{"UnknownBlock", "      a.in: zz.out\n", 13, 13, "unknown block 'p.zz'"},
        WireError{"UnknownPin", "      a.in: b.outt\n", 13, 13, "has no pin 'outt' (pins: in, out"},
        WireError{"UnknownDestBlock", "      x.in: a.out\n", 13, 7, "unknown block 'p.x'"},
        WireError{"UnknownDestPin", "      a.inn: b.out\n", 13, 7, "has no pin 'inn'"},
        WireError{"DestIsOutput", "      a.out: b.out\n", 13, 7, "is an output"},
        WireError{"SourceIsInput", "      a.in: b.in\n", 13, 13, "is an input"},
        WireError{"TypeMismatch", "      a.in: b.ticks\n", 13, 13,
                  "type mismatch: 'a.in' is LREAL but 'b.ticks' is LINT"},
        WireError{"BoolConstantOnReal", "      a.in: true\n", 13, 13, "does not fit LREAL"},
        WireError{"RealConstantOnBool", "      a.flag: 1.5\n", 13, 15, "does not fit BOOL"},
        WireError{"UnknownProgram", "      a.in: zz.b.out\n", 13, 13,
                  "no block 'zz' in program 'p' and no program 'zz'"},
        WireError{"UnknownIoPin", "      a.in: io.ai9\n", 13, 13, "has no pin 'ai9'"},
        WireError{"IoOutputAsDest", "      io.ai0: a.out\n", 13, 7, "is an output"},
        WireError{"NoChildPin", "      a.in: b.x.out\n", 13, 13, "has no pin 'x.out'"},
        WireError{"IoPinTooDeep", "      a.in: io.ai0.x\n", 13, 13, "I/O pins are named io.pin"},
        WireError{"TooManyParts", "      a.in: p.a.b.c.d.out\n", 13, 13,
                  "must be block.pin, program.block.pin, io.pin"}),
    [](const auto& tpi) { return std::string(tpi.param.name); });

TEST(BuildErrors, UnknownBlockTypeListsTheKnownOnes) {
  const rt::Diagnostic d =
      build_error(with_program("      - {name: a, type: AddOnee}\n", "      {}\n"));
  EXPECT_EQ(d.loc.line, 10);
  EXPECT_EQ(d.loc.col, 25);
  EXPECT_NE(d.message.find("unknown block type 'AddOnee' (known: "), std::string::npos) << d.str();
  EXPECT_NE(d.message.find("AddOne,"), std::string::npos) << d.str();
}

TEST(BuildErrors, BadParameterValuesAreReportedAtTheValue) {
  auto err = [](const std::string& params) {
    return build_error(with_program(
        "      - {name: a, type: ParamProbe, params: {" + params + "}}\n", "      {}\n"));
  };
  rt::Diagnostic d = err("gain: fast");
  EXPECT_EQ(d.loc.line, 10);
  EXPECT_EQ(d.loc.col, 52);
  EXPECT_NE(d.message.find("parameter 'gain' is LREAL, got 'fast'"), std::string::npos) << d.str();
  d = err("count: 2.5");
  EXPECT_NE(d.message.find("'count' is LINT"), std::string::npos) << d.str();
  d = err("enabled: 1");
  EXPECT_NE(d.message.find("'enabled' is BOOL"), std::string::npos) << d.str();
  d = err("hold: 5");
  EXPECT_NE(d.message.find("needs a unit"), std::string::npos) << d.str();
  d = err("gain: 500");
  EXPECT_NE(d.message.find("gain must be in [0, 100] (got 500)"), std::string::npos) << d.str();
  EXPECT_EQ(d.loc.col, 52);
  d = err("gian: 5");
  EXPECT_NE(d.message.find("unknown parameter 'gian'"), std::string::npos) << d.str();
  EXPECT_NE(d.message.find("gain, count, enabled, hold, label"), std::string::npos) << d.str();
  EXPECT_EQ(d.loc.col, 46);
}

TEST(BuildErrors, TraceAndRetainNamesMustExist) {
  std::string cfg = with_program(kChain, "      {}\n");
  rt::Diagnostic d = build_error(cfg + "trace: {variables: [p.a.out, p.a.nope]}\n");
  EXPECT_EQ(d.loc.line, 17);
  EXPECT_NE(d.message.find("trace: unknown variable 'p.a.nope'"), std::string::npos) << d.str();
  d = build_error(cfg + "bridge: {port: 0, status_vars: [p.a.out, p.a.nope]}\n");
  EXPECT_EQ(d.loc.line, 17);
  EXPECT_EQ(d.loc.col, 42);
  EXPECT_NE(d.message.find("bridge.status_vars: unknown variable 'p.a.nope'"), std::string::npos)
      << d.str();
  d = build_error(cfg + "retain: {file: /tmp/x.retain, variables: [p.a.in]}\n");
  EXPECT_NE(d.message.find("is an input"), std::string::npos) << d.str();
}

TEST(Forcing, ForcedOutputIsSeenByWiresUntilUnforced) {
  auto r = build_from_text(with_program(kChain, "      b.in: a.out\n"));
  Stepper s(*r);
  ASSERT_TRUE(r->variables().force("p.a.out", 10.0));
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 10.0) << "the block's own write is overridden";
  EXPECT_EQ(s.read("p.b.out"), 11.0) << "consumers see the forced value";
  EXPECT_EQ(r->variables().forced(), std::vector<std::string>{"p.a.out"});
  ASSERT_TRUE(r->variables().unforce("p.a.out"));
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 1.0);
  EXPECT_EQ(s.read("p.b.out"), 2.0);
  EXPECT_TRUE(r->variables().forced().empty());
}

TEST(Forcing, ForcedInputIgnoresItsWire) {
  auto r = build_from_text(with_program(kChain, "      b.in: a.out\n"));
  Stepper s(*r);
  ASSERT_TRUE(r->variables().force("p.b.in", -5.0));
  s.step();
  EXPECT_EQ(s.read("p.a.out"), 1.0);
  EXPECT_EQ(s.read("p.b.in"), -5.0);
  EXPECT_EQ(s.read("p.b.out"), -4.0);
}

TEST(Forcing, RefusesParametersUnknownNamesAndValuesOfTheWrongType) {
  auto r =
      build_from_text(with_program(kChain + "      - {name: c, type: ParamProbe}\n", "      {}\n"));
  auto& v = r->variables();
  EXPECT_EQ(v.force("p.c.gain", 1.0).result, rt::VarResult::kWrongKind);
  EXPECT_EQ(v.force("p.zz.out", 1.0).result, rt::VarResult::kNotFound);
  EXPECT_EQ(v.force("p.a.flag", 0.5).result, rt::VarResult::kTypeMismatch);
  EXPECT_EQ(v.force("p.a.ticks", 1.5).result, rt::VarResult::kTypeMismatch);
  EXPECT_EQ(v.force("p.a.in", std::nan("")).result, rt::VarResult::kTypeMismatch);
  EXPECT_TRUE(v.force("p.a.flag", 1.0));
  EXPECT_EQ(v.read("p.a.flag"), 1.0);
}

TEST(ParameterWrites, AreValidatedThenAppliedAtTheNextCycleStart) {
  auto r = build_from_text(
      with_program("      - {name: c, type: ParamProbe, params: {gain: 2}}\n", "      {}\n"));
  Stepper s(*r);
  auto& v = r->variables();
  s.step();
  EXPECT_EQ(s.read("p.c.gain_seen"), 2.0);
  ASSERT_TRUE(v.write("p.c.gain", 7.5));
  EXPECT_EQ(v.read("p.c.gain"), 7.5) << "reads show the accepted value";
  EXPECT_EQ(s.read("p.c.gain_seen"), 2.0) << "not applied until the next cycle";
  s.step();
  EXPECT_EQ(s.read("p.c.gain_seen"), 7.5);

  auto bad = v.write("p.c.gain", 500.0);
  EXPECT_EQ(bad.result, rt::VarResult::kInvalid);
  EXPECT_NE(bad.message.find("must be in [0, 100]"), std::string::npos) << bad.message;
  EXPECT_EQ(v.read("p.c.gain"), 7.5) << "a refused write changes nothing";
  s.step();
  EXPECT_EQ(s.read("p.c.gain_seen"), 7.5);

  EXPECT_EQ(v.write("p.c.count", 2.5).result, rt::VarResult::kTypeMismatch);
  EXPECT_EQ(v.write("p.c.count", 0.0).result, rt::VarResult::kInvalid);
  EXPECT_EQ(v.write("p.c.label", 1.0).result, rt::VarResult::kTypeMismatch);
  EXPECT_EQ(v.write("p.c.gain_seen", 1.0).result, rt::VarResult::kWrongKind);
  EXPECT_EQ(v.write("p.c.nope", 1.0).result, rt::VarResult::kNotFound);
  ASSERT_TRUE(v.write("p.c.hold", 0.25));
  EXPECT_EQ(v.read_param("p.c.hold")->i, 250'000'000);
}

TEST(ParameterWrites, AFullQueueAnswersBusyAndLosesNothingAccepted) {
  auto r = build_from_text(
      with_program("      - {name: c, type: ParamProbe, params: {gain: 2}}\n", "      {}\n"));
  Stepper s(*r);
  auto& v = r->variables();
  std::size_t accepted = 0;
  rt::VarStatus st;
  for (int i = 0; i < 1000 && (st = v.write("p.c.gain", 1.0 + i % 50)); ++i) {
    ++accepted;
  }
  EXPECT_EQ(st.result, rt::VarResult::kBusy);
  EXPECT_EQ(accepted, rt::Task::kParamQueueCapacity);
  const double last_accepted = 1.0 + static_cast<double>((accepted - 1) % 50);
  EXPECT_EQ(v.read("p.c.gain"), last_accepted) << "the refused write was rolled back";
  s.step();
  EXPECT_EQ(s.read("p.c.gain_seen"), last_accepted);
}

TEST(Variables, EveryPinAndParameterIsListedWithItsTaskAndType) {
  auto r = build_from_text(with_program(kChain, "      {}\n"));
  const auto& all = r->variables().all();
  auto find = [&](const std::string& n) { return r->variables().find(n); };
  ASSERT_NE(find("p.a.in"), nullptr);
  EXPECT_EQ(find("p.a.in")->kind, rt::VarKind::kInput);
  EXPECT_EQ(find("p.a.ticks")->type_name(), "LINT");
  EXPECT_EQ(find("io.ai0")->kind, rt::VarKind::kOutput);
  EXPECT_EQ(find("io.channels")->kind, rt::VarKind::kParam);
  EXPECT_EQ(find("q.b.out")->owner->name(), "fast");
  // 2 blocks × 4 pins in p, 4 in q, 2 channels × 4 loopback pins, 1 loopback parameter.
  EXPECT_EQ(all.size(), 8u + 4u + 8u + 1u);
}

}  // namespace
}  // namespace edm::test
