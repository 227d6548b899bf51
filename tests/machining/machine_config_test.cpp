// read_machine_tables(): machine.axes and conditions of a machine config, with the runtime
// loader's keys, ranges and defaults, and located errors for malformed input.
#include "edm/machining/machine_config.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace edm::machining {
namespace {

std::vector<std::string> errors_of(const std::string& yaml) {
  try {
    parse_machine_tables(yaml, "m.yaml");
  } catch (const MachineConfigError& e) {
    EXPECT_EQ(std::string(e.what()), e.messages().front());
    return e.messages();
  }
  ADD_FAILURE() << "accepted:\n" << yaml;
  return {};
}

TEST(MachineConfig, ReadsTheShippedDrillMachine) {
  const MachineTables t =
      read_machine_tables(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  ASSERT_EQ(t.axes.size(), 3u);
  const AxisLimits* z = t.axis('Z');
  ASSERT_NE(z, nullptr);
  EXPECT_EQ(z->min_mm, -60.0);
  EXPECT_EQ(z->max_mm, 20.0);
  EXPECT_EQ(z->v_max_mm_s, 30.0);
  const Condition* e1 = t.condition(1);
  ASSERT_NE(e1, nullptr);
  EXPECT_EQ(e1->name, "drill-rough");
  EXPECT_EQ(e1->polarity, Polarity::kNegative);
  EXPECT_EQ(e1->wear_ratio, 0.6189);  // the calibrated effective ratio (docs/blocks.md)
  EXPECT_EQ(e1->area_ratio, 1.3297);  // A_hole/A_e of the Ø1.0/0.3 tube in its Ø1.1 hole
  EXPECT_EQ(e1->tdr_us, 8.0);
  const Condition* e2 = t.condition(2);
  ASSERT_NE(e2, nullptr);
  EXPECT_EQ(e2->polarity, Polarity::kPositive);
}

TEST(MachineConfig, DefaultsAndOtherSectionsIgnored) {
  const MachineTables t = parse_machine_tables(
      "version: 1\n"
      "machine:\n"
      "  name: m\n"
      "  axes:\n"
      "    - {name: X, min_mm: -5, max_mm: 5}\n"
      "conditions:\n"
      "  - {E: 3}\n"
      "tasks: whatever the runtime checks\n",
      "m.yaml");
  ASSERT_EQ(t.axes.size(), 1u);
  EXPECT_EQ(t.axes[0].v_max_mm_s, 10.0);
  EXPECT_EQ(t.axes[0].a_max_mm_s2, 1000.0);
  ASSERT_EQ(t.conditions.size(), 1u);
  EXPECT_EQ(t.conditions[0].e, 3);
  EXPECT_EQ(t.conditions[0].polarity, Polarity::kNegative);
  EXPECT_EQ(t.conditions[0].tdr_us, 8.0);
  EXPECT_EQ(t.conditions[0].wear_ratio, 0.0);
}

TEST(MachineConfig, MalformedAxes) {
  const auto e = errors_of(
      "machine:\n"
      "  axes:\n"
      "    - {name: Q, min_mm: 0, max_mm: 1}\n"
      "    - {name: X, min_mm: 5, max_mm: 1}\n"
      "    - {name: X, min_mm: 0, max_mm: 1, speed: 3}\n"
      "    - {name: Y, min_mm: '0', max_mm: 1, v_max_mm_s: 0}\n"
      "    - {name: Z}\n");
  // The runtime's wording (one section reader): an axis with bad limits still claims its name.
  ASSERT_EQ(e.size(), 8u);
  EXPECT_EQ(e[0], "m.yaml:3:14: machine.axes[0].name: must be one of X, Y, Z (got 'Q')");
  EXPECT_EQ(e[1],
            "m.yaml:4:36: machine.axes[1].max_mm: must be > min_mm (got max_mm 1 <= min_mm 5)");
  EXPECT_EQ(e[2], "m.yaml:5:14: machine.axes[2].name: duplicate axis 'X' (first at line 4)");
  EXPECT_EQ(e[3].substr(0, 54), "m.yaml:5:39: machine.axes[2]: unknown key 'speed' (all");
  EXPECT_EQ(e[4], "m.yaml:6:25: machine.axes[3].min_mm: expected a number, got the string '0'");
  EXPECT_EQ(e[5], "m.yaml:6:53: machine.axes[3].v_max_mm_s: must be > 0 (got 0)");
  EXPECT_EQ(e[6], "m.yaml:7:7: machine.axes[4]: missing required key 'min_mm'");
  EXPECT_EQ(e[7], "m.yaml:7:7: machine.axes[4]: missing required key 'max_mm'");
}

TEST(MachineConfig, MalformedConditions) {
  const auto e = errors_of(
      "machine: {name: m}\n"
      "conditions:\n"
      "  - {E: 0}\n"
      "  - {E: 1, polarity: plus, wear_ratio: 11}\n"
      "  - {E: 1, name: again}\n"
      "  - {name: no-number, E: 2, E: 3}\n");
  const std::vector<std::string> expected{
      "m.yaml:3:9: conditions[0].E: must be in 1..2147483647 (got 0)",
      "m.yaml:4:22: conditions[1].polarity: must be one of negative, positive (got 'plus')",
      "m.yaml:4:40: conditions[1].wear_ratio: must be in 0..10 (got 11)",
      "m.yaml:5:9: conditions[2].E: duplicate condition E1 (first at line 4)",
      "m.yaml:6:29: conditions[3]: duplicate key 'E' (first at line 6)"};
  EXPECT_EQ(e, expected);
}

TEST(MachineConfig, SyntaxAndShapeErrors) {
  EXPECT_EQ(errors_of("machine: [\n").front().substr(0, 29), "m.yaml:2:1: YAML syntax error");
  EXPECT_EQ(errors_of("").front(),
            "m.yaml:1:1: the top level must be a map (version, machine, conditions, ...), got "
            "nothing (null)");
  EXPECT_EQ(errors_of("version: 1\n").front(), "m.yaml:1:1: missing required key 'machine'");
  EXPECT_EQ(errors_of("version: 2\nmachine: {}\n").front(),
            "m.yaml:1:10: version: unsupported version '2' (expected 1)");
  EXPECT_EQ(errors_of("machine: {axes: {name: X}}\n").front(),
            "m.yaml:1:17: machine.axes: expected a list, got a map");
}

TEST(MachineConfig, UnreadableFile) {
  try {
    read_machine_tables("/nonexistent/machine.yaml");
    FAIL() << "no exception";
  } catch (const MachineConfigError& e) {
    ASSERT_EQ(e.messages().size(), 1u);
    EXPECT_EQ(e.messages()[0],
              "/nonexistent/machine.yaml:1:1: cannot open: No such file or directory");
  }
}

}  // namespace
}  // namespace edm::machining
