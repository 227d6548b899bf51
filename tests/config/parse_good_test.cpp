// A config that uses every key parses to the expected values; defaults apply when keys are absent.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "edm/runtime/config.hpp"

namespace edm::rt {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;

const std::string kFullPath = std::string(EDM_TEST_DATA_DIR) + "/configs/good/full.yaml";

const ParamSetting* find_param(const std::vector<ParamSetting>& params, const std::string& key) {
  for (const ParamSetting& p : params) {
    if (p.key == key) {
      return &p;
    }
  }
  return nullptr;
}

const WireSpec* find_wire(const ProgramSpec& p, const std::string& dest) {
  for (const WireSpec& w : p.wires) {
    if (w.dest == dest) {
      return &w;
    }
  }
  return nullptr;
}

class FullConfigTest : public ::testing::Test {
 protected:
  void SetUp() override { cfg_ = parse_config_file(kFullPath); }
  Config cfg_;
};

// Axis `name` with limits `min_mm`..`max_mm`, v_max and a_max as given.
void expect_axis(const AxisSpec& a, char name, double min_mm, double max_mm, double v_max_mm_s,
                 double a_max_mm_s2) {
  EXPECT_EQ(a.name, name);
  EXPECT_DOUBLE_EQ(a.min_mm, min_mm);
  EXPECT_DOUBLE_EQ(a.max_mm, max_mm);
  EXPECT_DOUBLE_EQ(a.v_max_mm_s, v_max_mm_s);
  EXPECT_DOUBLE_EQ(a.a_max_mm_s2, a_max_mm_s2);
}

TEST_F(FullConfigTest, machine_io_and_axes) {
  EXPECT_EQ(cfg_.path, kFullPath);
  EXPECT_EQ(cfg_.version, 1);
  EXPECT_EQ(cfg_.machine.name, "drill-sim");
  EXPECT_EQ(cfg_.machine.loc.line, 5);
  EXPECT_EQ(cfg_.machine.io.driver, "loopback");
  EXPECT_EQ(cfg_.machine.io.driver_loc.line, 7);
  EXPECT_EQ(cfg_.machine.io.driver_loc.col, 13);
  ASSERT_TRUE(cfg_.machine.io.task.has_value());
  EXPECT_EQ(cfg_.machine.io.task->name, "fast");
  EXPECT_EQ(cfg_.machine.io.task->loc.line, 8);

  const auto& params = cfg_.machine.io.params;
  ASSERT_EQ(params.size(), 5u);
  EXPECT_EQ(params[0].key, "channels");  // file order is kept
  EXPECT_EQ(params[0].value, "4");
  EXPECT_FALSE(params[0].quoted);
  EXPECT_EQ(params[0].key_loc.line, 9);
  EXPECT_EQ(params[0].key_loc.col, 14);
  EXPECT_EQ(params[0].value_loc.col, 24);
  EXPECT_EQ(find_param(params, "seed")->value, "42");
  EXPECT_EQ(find_param(params, "label")->value, "7");
  EXPECT_TRUE(find_param(params, "label")->quoted);
  EXPECT_EQ(find_param(params, "gain")->value, "1.5");
  EXPECT_EQ(find_param(params, "invert")->value, "true");
  EXPECT_FALSE(find_param(params, "invert")->quoted);

  ASSERT_EQ(cfg_.machine.axes.size(), 2u);
  expect_axis(cfg_.machine.axes[0], 'X', -100.0, 100.0, 20.0, 800.0);
  const AxisSpec& z = cfg_.machine.axes[1];
  expect_axis(z, 'Z', -50.0, 5.5, 10.0, 500.0);
  EXPECT_EQ(z.loc.line, 12);
  EXPECT_EQ(z.loc.col, 7);
}

TEST_F(FullConfigTest, conditions_with_defaults) {
  ASSERT_EQ(cfg_.conditions.size(), 2u);
  const ConditionSpec& rough = cfg_.conditions[0];
  EXPECT_EQ(rough.e, 1);
  EXPECT_EQ(rough.name, "rough");
  EXPECT_EQ(rough.polarity, Polarity::kNegative);
  EXPECT_DOUBLE_EQ(rough.open_voltage_v, 120.0);
  EXPECT_DOUBLE_EQ(rough.peak_current_a, 10.0);
  EXPECT_DOUBLE_EQ(rough.on_time_us, 20.0);
  EXPECT_DOUBLE_EQ(rough.off_time_us, 40.0);
  EXPECT_DOUBLE_EQ(rough.tdr_us, 8.0);
  EXPECT_DOUBLE_EQ(rough.servo_ref_v, 40.0);
  EXPECT_DOUBLE_EQ(rough.wear_ratio, 0.05);

  const ConditionSpec& finish = cfg_.conditions[1];
  const ConditionSpec defaults;
  EXPECT_EQ(finish.e, 7);
  EXPECT_EQ(finish.name, "finish");
  EXPECT_EQ(finish.polarity, Polarity::kPositive);
  EXPECT_DOUBLE_EQ(finish.peak_current_a, 2.5);
  EXPECT_DOUBLE_EQ(finish.open_voltage_v, defaults.open_voltage_v);
  EXPECT_DOUBLE_EQ(finish.on_time_us, defaults.on_time_us);
  EXPECT_DOUBLE_EQ(finish.wear_ratio, defaults.wear_ratio);
  EXPECT_EQ(finish.loc.line, 16);
}

// An enabled watchdog of `time`, `sensitivity` and `action`.
void expect_watchdog(const WatchdogSpec& w, Duration time, int sensitivity, WatchdogAction action) {
  EXPECT_TRUE(w.enabled);
  EXPECT_EQ(w.time, time);
  EXPECT_EQ(w.sensitivity, sensitivity);
  EXPECT_EQ(w.action, action);
}

TEST_F(FullConfigTest, tasks) {
  ASSERT_EQ(cfg_.tasks.size(), 2u);
  const TaskSpec& fast = cfg_.tasks[0];
  EXPECT_EQ(fast.name, "fast");
  EXPECT_EQ(fast.name_loc.line, 21);
  EXPECT_EQ(fast.name_loc.col, 11);
  EXPECT_EQ(fast.interval, microseconds(250));
  EXPECT_EQ(fast.priority, 0);
  ASSERT_TRUE(fast.cpu.has_value());
  EXPECT_EQ(*fast.cpu, 1);
  EXPECT_EQ(fast.overrun, OverrunPolicy::kAsap);
  expect_watchdog(fast.watchdog, milliseconds(1), 3, WatchdogAction::kWarn);
  ASSERT_EQ(fast.programs.size(), 1u);
  EXPECT_EQ(fast.programs[0].name, "gap");
  EXPECT_EQ(fast.programs[0].loc.line, 27);
  EXPECT_EQ(fast.programs[0].loc.col, 16);

  const TaskSpec& slow = cfg_.tasks[1];
  EXPECT_EQ(slow.name, "slow");
  EXPECT_EQ(slow.interval, milliseconds(10));
  EXPECT_EQ(slow.priority, 5);
  EXPECT_FALSE(slow.cpu.has_value());
  EXPECT_EQ(slow.overrun, OverrunPolicy::kSkip);
  expect_watchdog(slow.watchdog, milliseconds(20), 1, WatchdogAction::kFault);
  ASSERT_EQ(slow.programs.size(), 2u);
  EXPECT_EQ(slow.programs[0].name, "supervisor");
  EXPECT_EQ(slow.programs[1].name, "logger");
}

TEST_F(FullConfigTest, programs_blocks_params_and_wires) {
  ASSERT_EQ(cfg_.programs.size(), 3u);
  const ProgramSpec& gap = cfg_.programs[0];
  EXPECT_EQ(gap.name, "gap");
  EXPECT_EQ(gap.name_loc.line, 34);
  ASSERT_EQ(gap.blocks.size(), 2u);
  EXPECT_EQ(gap.blocks[0].name, "lp");
  EXPECT_EQ(gap.blocks[0].type, "LowPass");
  EXPECT_EQ(gap.blocks[0].type_loc.line, 36);
  EXPECT_EQ(gap.blocks[0].type_loc.col, 26);
  ASSERT_EQ(gap.blocks[0].params.size(), 1u);
  EXPECT_EQ(gap.blocks[0].params[0].key, "tau");
  EXPECT_EQ(gap.blocks[0].params[0].value, "5ms");
  EXPECT_FALSE(gap.blocks[0].params[0].quoted);

  const BlockSpec& ctl = gap.blocks[1];
  EXPECT_EQ(ctl.name, "ctl");
  EXPECT_EQ(ctl.type, "GapControllerP");
  EXPECT_EQ(ctl.name_loc.line, 37);
  EXPECT_EQ(ctl.loc.line, 37);
  ASSERT_EQ(ctl.params.size(), 3u);
  EXPECT_EQ(find_param(ctl.params, "kp")->value, "0.8");
  const ParamSetting* label = find_param(ctl.params, "label");
  ASSERT_NE(label, nullptr);
  EXPECT_EQ(label->value, "1.0");
  EXPECT_TRUE(label->quoted);  // "1.0" quoted is a string, not a number
  EXPECT_EQ(label->value_loc.line, 41);
  EXPECT_EQ(find_param(ctl.params, "enabled")->value, "true");

  ASSERT_EQ(gap.wires.size(), 5u);
  const WireSpec* in = find_wire(gap, "lp.in");
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->source, "io.ai0");
  EXPECT_TRUE(in->source_is_name);
  EXPECT_EQ(in->dest_loc.line, 44);
  EXPECT_EQ(in->dest_loc.col, 7);
  EXPECT_EQ(in->source_loc.col, 14);
  EXPECT_TRUE(find_wire(gap, "ctl.in")->source_is_name);
  EXPECT_EQ(find_wire(gap, "ctl.ref")->source, "40");
  EXPECT_FALSE(find_wire(gap, "ctl.ref")->source_is_name);
  EXPECT_EQ(find_wire(gap, "ctl.enable")->source, "true");
  EXPECT_FALSE(find_wire(gap, "ctl.enable")->source_is_name);
  EXPECT_EQ(find_wire(gap, "io.ao0")->source, "ctl.out");
  EXPECT_EQ(gap.wires[0].dest, "lp.in");  // file order is kept

  const ProgramSpec& sup = cfg_.programs[1];
  EXPECT_EQ(sup.name, "supervisor");
  ASSERT_EQ(sup.wires.size(), 1u);
  EXPECT_EQ(sup.wires[0].source, "gap.ctl.out");
  EXPECT_TRUE(sup.wires[0].source_is_name);
  EXPECT_TRUE(cfg_.programs[2].blocks.empty());
  EXPECT_TRUE(cfg_.programs[2].wires.empty());
}

TEST_F(FullConfigTest, trace_bridge_retain) {
  ASSERT_EQ(cfg_.trace.variables.size(), 2u);
  EXPECT_EQ(cfg_.trace.variables[0].name, "gap.lp.out");
  EXPECT_EQ(cfg_.trace.variables[1].name, "io.ai0");
  EXPECT_EQ(cfg_.trace.variables[1].loc.line, 57);
  EXPECT_EQ(cfg_.trace.variables[1].loc.col, 27);
  EXPECT_EQ(cfg_.trace.capacity, 4096u);

  EXPECT_EQ(cfg_.bridge.bind, "0.0.0.0");
  EXPECT_EQ(cfg_.bridge.port, 7731);
  EXPECT_EQ(cfg_.bridge.token_file, "/etc/edmplc/operator.token");
  EXPECT_EQ(cfg_.bridge.viewer_token_file, "/etc/edmplc/viewer.token");
  EXPECT_EQ(cfg_.bridge.max_sessions, 4);
  EXPECT_EQ(cfg_.bridge.max_line_bytes, 65536u);

  EXPECT_EQ(cfg_.retain.file, "build/retain.dat");
  EXPECT_EQ(cfg_.retain.min_interval, seconds(2));
  ASSERT_EQ(cfg_.retain.variables.size(), 1u);
  EXPECT_EQ(cfg_.retain.variables[0].name, "supervisor.counter.count");
}

TEST(MinimalConfig, optional_sections_take_struct_defaults) {
  const Config cfg = parse_config_text(
      "version: 1\n"
      "machine: {name: m}\n"
      "tasks: [{name: t, interval: 2ms, programs: [p]}]\n"
      "programs: [{name: p}]\n",
      "min.yaml");
  const Config defaults;
  EXPECT_EQ(cfg.machine.io.driver, "loopback");
  EXPECT_FALSE(cfg.machine.io.task.has_value());
  EXPECT_TRUE(cfg.machine.axes.empty());
  EXPECT_TRUE(cfg.conditions.empty());
  EXPECT_EQ(cfg.tasks[0].priority, 0);
  EXPECT_FALSE(cfg.tasks[0].watchdog.enabled);
  EXPECT_EQ(cfg.tasks[0].overrun, OverrunPolicy::kSkip);
  EXPECT_TRUE(cfg.programs[0].blocks.empty());
  EXPECT_EQ(cfg.trace.capacity, defaults.trace.capacity);
  EXPECT_EQ(cfg.bridge.bind, defaults.bridge.bind);
  EXPECT_EQ(cfg.bridge.port, defaults.bridge.port);
  EXPECT_EQ(cfg.bridge.max_sessions, defaults.bridge.max_sessions);
  EXPECT_EQ(cfg.bridge.max_line_bytes, defaults.bridge.max_line_bytes);
  EXPECT_TRUE(cfg.retain.file.empty());
}

TEST(ShippedConfigs, machine_and_bench_configs_parse) {
  // The shipped machine and bench configs must at least pass the parser (the builder checks
  // the rest). Other YAML under config/ (condition tables) may follow other schemas.
  int n = 0;
  for (const char* dir : {"/config/machines", "/config/bench"}) {
    std::error_code ec;
    for (const auto& e :
         std::filesystem::directory_iterator(std::string(EDM_SOURCE_DIR) + dir, ec)) {
      if (e.path().extension() != ".yaml") {
        continue;
      }
      ++n;
      try {
        parse_config_file(e.path().string());
      } catch (const ConfigError& err) {
        ADD_FAILURE() << err.what();
      }
    }
  }
  if (n == 0) {
    GTEST_SKIP() << "no configs under config/machines or config/bench yet";
  }
}

}  // namespace
}  // namespace edm::rt
