// The controller blocks through the YAML loader: the fuzzy term/rule text arrives as string
// parameters, and a malformed rule is reported with the file position of the parameter and the
// line/column inside the text.

#include <gtest/gtest.h>

#include <string>

#include "edm/blocks/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "support/files.hpp"

namespace edm::blocks {
namespace {

std::unique_ptr<rt::Runtime> build(const std::string& yaml) {
  static const auto regs = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    register_builtin_blocks(r.first);
    rt::register_runtime_drivers(r.second);
    return r;
  }();
  return rt::Runtime::build(rt::parse_config_text(yaml, "ctl.yaml"), regs.first, regs.second);
}

// A seed-003/000 program on a loopback machine whose FuzzyServoLUT has these `rules` (YAML text).
std::string config(const std::string& rules) {
  return edm::test::test_data("controllers/fuzzy_program.yaml", {{"rules", rules}});
}

TEST(ControllersConfig, a_full_seed_003_and_000_program_loads_from_yaml) {
  const std::string rules =
      "\"if open is L then v is PB; if short is L then v is NB; if open is Z and short is Z "
      "then v is ZE; if open is M and short is Z then v is PS; if open is Z and short is M then v "
      "is NS; if open is M and short is M then v is ZE\"";
  auto r = build(config(rules));
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->variables().read("p.pi.ku"), 0.08);
  EXPECT_EQ(r->variables().read("p.gm.horizon"), 37.0);
}

TEST(ControllersConfig, a_malformed_rule_names_the_yaml_position_and_the_text_position) {
  try {
    build(config("\"if open is L and short is Z than v is PB\""));
    FAIL() << "accepted";
  } catch (const rt::ConfigError& e) {
    const std::string msg = e.diagnostics().front().str();
    EXPECT_NE(msg.find("ctl.yaml:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rules"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rules at line 1, column 29: expected 'and' or 'then', found 'than'"),
              std::string::npos)
        << msg;
  }
}

}  // namespace
}  // namespace edm::blocks
