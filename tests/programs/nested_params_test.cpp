// One block model all the way down (issue 18): a C++ PROGRAM's child parameters are variables
// `program.block.child.param` — listed, set from YAML (nested map or dotted key), written at run
// time over the bridge and applied by the owning task at the start of its next cycle — and a
// fault a child raises names that child.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/gap_controller_p.hpp"
#include "edm/blocks/linear_interpolator.hpp"
#include "edm/blocks/orbit_expander.hpp"
#include "edm/blocks/polarity_switch.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/blocks/wear_compensator.hpp"
#include "edm/bridge/client.hpp"
#include "edm/bridge/server.hpp"
#include "edm/programs/deep_hole_drill.hpp"
#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

// Runs the first task of `r` one 1 ms cycle per call on its own virtual clock (trace detached).
struct CycleByCycle {
  rt::VirtualClock clock;
  rt::Task& task;
  rt::TimePoint t{};
  explicit CycleByCycle(rt::Runtime& r) : task(*r.tasks()[0]) { task.detach_trace(); }
  void operator()() {
    clock.advance_to(t);
    task.run_cycle(t, clock);
    t += 1ms;
  }
};

const std::string kDrillProgram =
    std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim-program.yaml";
const std::string kDemo = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";

std::vector<std::string> param_names(rt::Block& b) {
  struct Names final : rt::ParamVisitor {
    std::vector<std::string> out;
    void on_param(std::string_view n, rt::ParamRef, rt::ParamSpec) override { out.emplace_back(n); }
  } v;
  b.visit_params(v);
  return v.out;
}

// Every parameter of a child type, checked under `prefix` on a built machine.
template <class B>
void expect_child_params(const rt::VariableRegistry& vars, const std::string& prefix) {
  B fresh;
  const std::vector<std::string> names = param_names(fresh);
  ASSERT_FALSE(names.empty()) << prefix;
  for (const std::string& n : names) {
    const rt::Variable* v = vars.find(prefix + "." + n);
    ASSERT_NE(v, nullptr) << prefix << "." << n;
    EXPECT_EQ(v->kind, rt::VarKind::kParam) << v->name;
  }
}

TEST(NestedParams, EveryChildParameterOfTheDemoMachineIsAVariable) {
  auto r = build_sim_machine(rt::parse_config_file(kDemo));
  const rt::VariableRegistry& vars = r->variables();
  expect_child_params<blocks::GapControllerP>(vars, "cnc.job.drill.gap");
  expect_child_params<blocks::TdDetector>(vars, "cnc.job.drill.td");
  expect_child_params<blocks::WearCompensator>(vars, "cnc.job.drill.wear");
  expect_child_params<blocks::PolaritySwitch>(vars, "cnc.job.finish.pol");
  expect_child_params<blocks::TdDetector>(vars, "cnc.job.finish.td");
  expect_child_params<blocks::OrbitExpander>(vars, "cnc.job.finish.orbit");
  expect_child_params<blocks::PositionLoop>(vars, "cnc.job.finish.px");
  expect_child_params<blocks::LinearInterpolator>(vars, "cnc.job.lin");
  expect_child_params<blocks::CircularInterpolator>(vars, "cnc.job.arc");
  for (const char* loop : {"cnc.job.px", "cnc.job.py", "cnc.job.pz"}) {
    expect_child_params<blocks::PositionLoop>(vars, loop);
  }
  const rt::Variable* kg = vars.find("cnc.job.drill.gap.kg");
  ASSERT_NE(kg, nullptr);
  EXPECT_EQ(kg->range, "(0, 10]");
  EXPECT_FALSE(kg->load_time_only);
  EXPECT_TRUE(vars.find("cnc.job.drill.td.window")->load_time_only);
}

// `edmplc --list-vars` prints rt::list_row() of every variable.
TEST(NestedParams, ListVarsOfTheDemoMachineShowsKgWithItsMetadata) {
  auto r = build_sim_machine(rt::parse_config_file(kDemo));
  const rt::Variable* kg = r->variables().find("cnc.job.drill.gap.kg");
  ASSERT_NE(kg, nullptr);
  const std::string row = rt::list_row(*kg);
  EXPECT_EQ(row.rfind("cnc.job.drill.gap.kg\tparam\tLREAL\tmm/s/us\t", 0), 0u) << row;
  EXPECT_NE(row.find("\t(0, 10]\truntime\t"), std::string::npos) << row;
  const std::string window = rt::list_row(*r->variables().find("cnc.job.drill.td.window"));
  EXPECT_NE(window.find("\t[1, 65536]\tload-time\t"), std::string::npos) << window;
}

std::string with_gap_params(const std::string& gap_yaml) {
  std::string text = read_file(kDrillProgram);
  const std::string from = "wear: {wear_ratio_default: 0.6166}";
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, from.size(), from + ", " + gap_yaml);
  return text;
}

double read_kg(const std::string& text) {
  auto r = build_sim_machine(rt::parse_config_text(text, "drill.yaml"));
  return r->variables().read("cycle.drill.gap.kg").value_or(-1.0);
}

TEST(NestedParams, KgIsSetFromYamlAsANestedMapOrADottedKey) {
  EXPECT_DOUBLE_EQ(read_kg(read_file(kDrillProgram)), blocks::GapControllerPParams{}.kg);
  EXPECT_DOUBLE_EQ(read_kg(with_gap_params("gap: {kg: 0.147}")), 0.147);
  EXPECT_DOUBLE_EQ(read_kg(with_gap_params("gap.kg: 0.147")), 0.147);
}

TEST(NestedParams, BadChildParametersAreRefusedAtTheirLine) {
  const auto first_error = [](const std::string& text) {
    try {
      build_sim_machine(rt::parse_config_text(text, "drill.yaml"));
    } catch (const rt::ConfigError& e) {
      return e.diagnostics().front();
    }
    ADD_FAILURE() << "accepted";
    return rt::Diagnostic{};
  };
  // The drill block's line in drill-sim-program.yaml.
  const std::string text = read_file(kDrillProgram);
  const auto at = text.find("{name: drill, type: DeepHoleDrill");
  ASSERT_NE(at, std::string::npos);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  rt::Diagnostic d = first_error(with_gap_params("gap: {kg: -1}"));
  EXPECT_EQ(d.loc.line, line) << d.str();
  EXPECT_NE(d.message.find("gap.kg must be in (0, 10] (got -1)"), std::string::npos) << d.str();
  d = first_error(with_gap_params("gap: {kg: 0.1}, gap.kg: 0.2"));
  EXPECT_NE(d.message.find("parameter 'gap.kg' is set twice"), std::string::npos) << d.str();
  d = first_error(with_gap_params("gap: {kgg: 0.1}"));
  EXPECT_NE(d.message.find("unknown parameter 'gap.kgg'"), std::string::npos) << d.str();
  d = first_error(with_gap_params("td: {window: 0}"));
  EXPECT_NE(d.message.find("td.window must be in [1, 65536] (got 0)"), std::string::npos)
      << d.str();
}

// The drilling machine driven cycle by cycle on the virtual clock, with a bridge server: the
// operator's var.write of Kg is accepted, then the next cycle's gap command follows the new Kg.
TEST(NestedParams, ABridgeWriteOfKgActsOnTheNextCycle) {
  auto r = build_sim_machine(rt::parse_config_file(kDrillProgram));
  r->machine().command(rt::MachineCommand::kPowerOn);
  bridge::ServerOptions so;
  so.port = 0;
  bridge::Server server(*r, so);
  server.start();
  bridge::Client client;
  bridge::ClientOptions co;
  co.port = server.port();
  co.timeout = 10s;
  ASSERT_EQ(client.connect(co), bridge::Role::kOperator);

  CycleByCycle cycle(*r);
  rt::VariableRegistry& vars = r->variables();
  const auto value = [&](const char* name) { return vars.read(name).value_or(NAN); };
  // Into DRILL, then 0.5 s of gap control.
  for (int k = 0; k < 20000 && value("cycle.drill.state") != 2.0; ++k) cycle();
  ASSERT_EQ(value("cycle.drill.state"), 2.0);
  for (int k = 0; k < 500; ++k) cycle();

  const double tdr = blocks::GapControllerPParams{}.tdr_default_us;
  const auto p_law = [&](double kg) {
    return std::clamp(kg * (tdr - value("cycle.drill.td.td_us")), -1.0, 5.0);
  };
  ASSERT_EQ(value("cycle.drill.td.valid"), 1.0);
  EXPECT_DOUBLE_EQ(value("cycle.drill.gap.vz_mm_s"), p_law(0.05));

  const bridge::Reply w =
      client.request("var.write", {{"name", "cycle.drill.gap.kg"}, {"value", 0.02}});
  ASSERT_TRUE(w) << w.body.dump();
  EXPECT_EQ(client.request("var.read", {{"name", "cycle.drill.gap.kg"}})
                .body["values"]["cycle.drill.gap.kg"],
            0.02);
  cycle();
  ASSERT_EQ(value("cycle.drill.td.valid"), 1.0);
  EXPECT_DOUBLE_EQ(value("cycle.drill.gap.vz_mm_s"), p_law(0.02));

  // A load-time child parameter and an out-of-range value are refused, and change nothing.
  const bridge::Reply window =
      client.request("var.write", {{"name", "cycle.drill.td.window"}, {"value", 16}});
  EXPECT_FALSE(window);
  EXPECT_NE(window.message.find("load time only"), std::string::npos) << window.message;
  const bridge::Reply negative =
      client.request("var.write", {{"name", "cycle.drill.gap.kg"}, {"value", -1.0}});
  EXPECT_FALSE(negative);
  EXPECT_NE(negative.message.find("gap.kg': out of range: must be in (0, 10] mm/s/us (got -1)"),
            std::string::npos)
      << negative.message;
  EXPECT_EQ(value("cycle.drill.gap.kg"), 0.02);
  EXPECT_NE(p_law(0.02), p_law(0.05));
  server.stop();
}

// A non-finite external servo command is the drill's own fault; a broken Td counter is the
// td child's, and the alarm names it.
TEST(NestedParams, AFaultNamesTheChildThatRaisedIt) {
  auto r = build_sim_machine(rt::parse_config_file(kDrillProgram));
  r->machine().command(rt::MachineCommand::kPowerOn);
  CycleByCycle cycle(*r);
  for (int k = 0; k < 20000 && r->variables().read("cycle.drill.state") != 2.0; ++k) cycle();
  ASSERT_TRUE(r->variables().force("cycle.drill.td.td_count", -5.0));  // an impossible counter
  cycle();  // the td child faults: alarm, FAULT (the next cycle releases the force and clears it)
  rt::ActiveAlarm alarms[16];
  const std::size_t n = r->machine().active_alarms(alarms, 16);
  const bool named = std::any_of(alarms, alarms + n, [](const rt::ActiveAlarm& a) {
    return a.code == rt::AlarmCode::kBlockFault && std::string(a.source) == "cycle.drill.td";
  });
  std::string seen;
  for (std::size_t k = 0; k < n; ++k) {
    seen += std::to_string(static_cast<int>(alarms[k].code)) + "@" + alarms[k].source + " ";
  }
  EXPECT_TRUE(named) << seen;
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
  // Issue 33: the alarm says why, in the td detector's words, with the value that tripped it.
  for (std::size_t k = 0; k < n; ++k) {
    if (alarms[k].code != rt::AlarmCode::kBlockFault) continue;
    EXPECT_STREQ(alarms[k].text, "a pulse counter out of range, or not configured");
    EXPECT_TRUE(std::isfinite(alarms[k].value)) << "the total of the counters that disagreed";
  }
}

}  // namespace
}  // namespace edm::test
