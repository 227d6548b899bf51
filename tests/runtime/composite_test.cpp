// C++ PROGRAM types: a composite block owns and steps its children; their pins are variables.

#include <gtest/gtest.h>

#include "support/runtime_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

// One task running program p, whose blocks follow.
constexpr const char* kProgramP = R"(version: 1
machine: {name: t}
tasks:
  - {name: fast, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
)";

const std::string kSequencer =
    std::string(kProgramP) + R"(      - {name: seq, type: TwoStep, params: {target: 3}}
      - {name: after, type: AddOne}
    wires:
      after.in: seq.fill.out
trace:
  variables: [p.seq.step, p.seq.fill.out]
)";

TEST(CompositeBlock, ChildrenPinsAreVariablesAndTheSequencerStepsThem) {
  run_log().clear();
  run_log().reserve(100);
  auto r = build_from_text(kSequencer);
  auto& vars = r->variables();
  ASSERT_NE(vars.find("p.seq.step"), nullptr);
  ASSERT_NE(vars.find("p.seq.fill.out"), nullptr);
  ASSERT_NE(vars.find("p.seq.drain.count"), nullptr);
  EXPECT_EQ(vars.find("p.seq.fill.in")->kind, rt::VarKind::kInput);
  rt::VirtualClock clock;
  r->machine().command(rt::MachineCommand::kPowerOn);
  auto& task = *r->tasks()[0];
  auto step = [&](int k) {
    const rt::TimePoint t{1ms * k};
    clock.advance_to(t);
    task.run_cycle(t, clock);
  };
  // fill counts 1, 2, 3 (its own output fed back), then the sequencer moves to step 1.
  for (int k = 0; k < 3; ++k) {
    step(k);
    EXPECT_EQ(vars.read("p.seq.fill.out"), k + 1.0);
    EXPECT_EQ(vars.read("p.after.out"), k + 2.0) << "wired from a child's pin";
  }
  EXPECT_EQ(vars.read("p.seq.step"), 1.0);
  EXPECT_EQ(vars.read("p.seq.drain.count"), 0.0);
  step(3);
  step(4);
  EXPECT_EQ(vars.read("p.seq.fill.out"), 3.0) << "step 1 no longer runs fill";
  EXPECT_EQ(vars.read("p.seq.drain.count"), 2.0);

  // A fault reaches the composite's children and parks the sequencer.
  rt::Alarm a;
  a.code = rt::AlarmCode::kBlockFault;
  r->machine().raise(a);
  step(5);
  EXPECT_EQ(vars.read("p.seq.step"), 0.0);
  auto* seq = dynamic_cast<TwoStep*>(r->program("p")->find("seq"));
  ASSERT_NE(seq, nullptr);
  EXPECT_EQ(seq->safe_entries, 1);
}

TEST(CompositeBlock, ChildPinsCanBeForced) {
  auto r = build_from_text(kSequencer);
  rt::VirtualClock clock;
  ASSERT_TRUE(r->variables().force("p.seq.fill.out", 10.0));
  r->tasks()[0]->run_cycle(rt::TimePoint{0}, clock);
  EXPECT_EQ(r->variables().read("p.seq.step"), 1.0) << "the forced child output drove the step";
}

TEST(CompositeBlock, ParameterErrorsAreLocatedAtTheComposite) {
  const rt::Diagnostic d = build_error(std::string(kProgramP) +
                                       R"(      - {name: seq, type: TwoStep, params: {target: -1}}
)");
  EXPECT_EQ(d.loc.line, 8);
  EXPECT_NE(d.message.find("target must be > 0"), std::string::npos) << d.str();
}

TEST(CompositeBlock, ChildParametersAreVariablesSetUnderTheCompositesParams) {
  const std::string base =
      std::string(kProgramP) + R"(      - {name: seq, type: TwoStep, params: )";
  auto r = build_from_text(base + "{target: 3, drain: {tag: dr}}}\n");
  const rt::Variable* tag = r->variables().find("p.seq.drain.tag");
  ASSERT_NE(tag, nullptr);
  EXPECT_EQ(tag->kind, rt::VarKind::kParam);
  EXPECT_EQ(r->variables().find("p.seq.target")->kind, rt::VarKind::kParam);
  EXPECT_NO_THROW(build_from_text(base + "{drain.tag: dr}}\n"));
  const rt::Diagnostic twice = build_error(base + "{drain.tag: a, drain: {tag: b}}}\n");
  EXPECT_EQ(twice.loc.line, 8);
  EXPECT_NE(twice.message.find("parameter 'drain.tag' is set twice"), std::string::npos)
      << twice.str();
  const rt::Diagnostic unknown = build_error(base + "{drain: {tagg: b}}}\n");
  EXPECT_NE(unknown.message.find("unknown parameter 'drain.tagg'"), std::string::npos)
      << unknown.str();
}

}  // namespace
}  // namespace edm::test
