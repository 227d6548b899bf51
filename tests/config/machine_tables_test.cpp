// One reader of machine.axes and conditions: the runtime's config path (parse_config_file →
// to_machine_tables) and the HMI's (machining::read_machine_tables, edmhmi check) must give the
// same tables for every shipped machine and the same file:line:col messages for a bad section.
#include "edm/machining/machine_tables.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "edm/machining/machine_config.hpp"
#include "edm/runtime/config.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;

void expect_same_tables(const machining::MachineTables& a, const machining::MachineTables& b,
                        const std::string& what) {
  ASSERT_EQ(a.axes.size(), b.axes.size()) << what;
  for (std::size_t i = 0; i < a.axes.size(); ++i) {
    SCOPED_TRACE(what + " axis " + std::to_string(i));
    EXPECT_EQ(a.axes[i].name, b.axes[i].name);
    EXPECT_EQ(a.axes[i].min_mm, b.axes[i].min_mm);
    EXPECT_EQ(a.axes[i].max_mm, b.axes[i].max_mm);
    EXPECT_EQ(a.axes[i].v_max_mm_s, b.axes[i].v_max_mm_s);
    EXPECT_EQ(a.axes[i].a_max_mm_s2, b.axes[i].a_max_mm_s2);
  }
  ASSERT_EQ(a.conditions.size(), b.conditions.size()) << what;
  for (std::size_t i = 0; i < a.conditions.size(); ++i) {
    SCOPED_TRACE(what + " condition " + std::to_string(i));
    const machining::Condition& x = a.conditions[i];
    const machining::Condition& y = b.conditions[i];
    EXPECT_EQ(x.e, y.e);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.polarity, y.polarity);
    EXPECT_EQ(x.open_voltage_v, y.open_voltage_v);
    EXPECT_EQ(x.peak_current_a, y.peak_current_a);
    EXPECT_EQ(x.on_time_us, y.on_time_us);
    EXPECT_EQ(x.off_time_us, y.off_time_us);
    EXPECT_EQ(x.tdr_us, y.tdr_us);
    EXPECT_EQ(x.servo_ref_v, y.servo_ref_v);
    EXPECT_EQ(x.wear_ratio, y.wear_ratio);
  }
}

std::vector<std::string> runtime_errors(const std::string& text, const std::string& file) {
  try {
    parse_config_text(text, file);
  } catch (const ConfigError& e) {
    std::vector<std::string> out;
    for (const Diagnostic& d : e.diagnostics()) out.push_back(d.str());
    return out;
  }
  return {};
}

std::vector<std::string> hmi_errors(const std::string& text, const std::string& file) {
  try {
    machining::parse_machine_tables(text, file);
  } catch (const machining::MachineConfigError& e) {
    return e.messages();
  }
  return {};
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(MachineTables, RuntimeAndHmiReadEveryShippedMachineAlike) {
  int machines = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(EDM_SOURCE_DIR) / "config/machines")) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string path = entry.path().string();
    const Config cfg = parse_config_file(path);
    const machining::MachineTables runtime_side = to_machine_tables(cfg);
    const machining::MachineTables hmi_side = machining::read_machine_tables(path);
    expect_same_tables(runtime_side, hmi_side, path);
    if (cfg.machine.axes.empty() && cfg.conditions.empty()) continue;  // a program-only file
    EXPECT_FALSE(runtime_side.axes.empty() && runtime_side.conditions.empty()) << path;
    ++machines;
  }
  EXPECT_GE(machines, 3);  // drill, sink and wire at least
}

TEST(MachineTables, SameMessageForABadCondition) {
  const std::string path = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";
  std::string text = read_text(path);
  const std::string good = "polarity: negative, open_voltage_v: 100";
  const auto at = text.find(good);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, good.size(), "polarity: plus, open_voltage_v: '100'");
  // Under its own path: its `include:` finds the fragment beside it.
  const std::vector<std::string> rt = runtime_errors(text, path);
  ASSERT_EQ(rt.size(), 2u);
  EXPECT_NE(rt[0].find("conditions[0].polarity: must be one of negative, positive (got 'plus')"),
            std::string::npos);
  EXPECT_NE(rt[1].find("conditions[0].open_voltage_v: expected a number, got the string '100'"),
            std::string::npos);
  EXPECT_EQ(hmi_errors(text, path), rt);
}

// Every bad config of tests/configs/bad whose fault is in machine.axes or conditions: the HMI's
// reader reports exactly what the runtime reports (message and place).
TEST(MachineTables, SameMessagesForEveryBadAxisAndConditionConfig) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(EDM_TEST_DATA_DIR) / "configs/bad")) {
    const std::string stem = entry.path().stem().string();
    if (stem.rfind("axis_", 0) != 0 && stem.rfind("condition_", 0) != 0) continue;
    const std::string text = read_text(entry.path());
    const std::vector<std::string> rt = runtime_errors(text, stem + ".yaml");
    ASSERT_FALSE(rt.empty()) << stem;
    EXPECT_EQ(hmi_errors(text, stem + ".yaml"), rt) << stem;
    ++files;
  }
  EXPECT_GE(files, 7);
}

}  // namespace
}  // namespace edm::rt
