// Every file in tests/configs/bad/ states its first error on line 1:
//   # expect: LINE:COL: <substring of the message>
// The parser (in process) and `edmplc --check` (as a subprocess) must both report exactly that.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "edm/apps/subprocess.hpp"
#include "edm/runtime/config.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;

struct BadCase {
  std::string path;
  std::string name;  // file stem, for test names
  int line{0};
  int col{0};
  std::string message;  // substring expected in the first diagnostic
  std::string header;   // line 1 as written, for failure messages
};

// Keeps gtest/ctest names readable instead of a byte dump of the struct.
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.path; }

std::vector<BadCase> load_cases() {
  std::vector<BadCase> cases;
  std::error_code ec;
  const fs::path dir = fs::path(EDM_TEST_DATA_DIR) / "configs" / "bad";
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() != ".yaml") {
      continue;
    }
    BadCase c;
    c.path = e.path().string();
    c.name = e.path().stem().string();
    std::replace_if(
        c.name.begin(), c.name.end(), [](char ch) { return std::isalnum(ch) == 0; }, '_');
    std::ifstream in(e.path());
    std::getline(in, c.header);
    const std::string prefix = "# expect: ";
    if (c.header.rfind(prefix, 0) == 0) {
      // "LINE:COL: message"; a malformed header leaves line 0 and fails the test below.
      const std::string rest = c.header.substr(prefix.size());
      const std::size_t c1 = rest.find(':');
      const std::size_t c2 = c1 == std::string::npos ? c1 : rest.find(':', c1 + 1);
      if (c2 != std::string::npos && c2 + 2 <= rest.size()) {
        c.line = std::atoi(rest.substr(0, c1).c_str());
        c.col = std::atoi(rest.substr(c1 + 1, c2 - c1 - 1).c_str());
        c.message = rest.substr(c2 + 2);
      }
    }
    cases.push_back(std::move(c));
  }
  std::sort(cases.begin(), cases.end(),
            [](const BadCase& a, const BadCase& b) { return a.name < b.name; });
  return cases;
}

const std::vector<BadCase>& cases() {
  static const std::vector<BadCase> kCases = load_cases();
  return kCases;
}

std::string case_name(const ::testing::TestParamInfo<BadCase>& info) { return info.param.name; }

TEST(BadConfigs, directory_holds_at_least_fifteen_cases) { EXPECT_GE(cases().size(), 15u); }

class BadConfigParse : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadConfigParse, first_diagnostic_matches_expectation) {
  const BadCase& c = GetParam();
  ASSERT_GT(c.line, 0) << c.path << ": line 1 must be '# expect: LINE:COL: message', got '"
                       << c.header << "'";
  ASSERT_FALSE(c.message.empty()) << c.path;
  try {
    parse_config_file(c.path);
    FAIL() << c.path << " parsed without error";
  } catch (const ConfigError& e) {
    ASSERT_FALSE(e.diagnostics().empty());
    const Diagnostic& d = e.diagnostics().front();
    EXPECT_EQ(d.loc.file, c.path);
    EXPECT_EQ(d.loc.line, c.line) << d.str();
    EXPECT_EQ(d.loc.col, c.col) << d.str();
    EXPECT_NE(d.message.find(c.message), std::string::npos)
        << "expected '" << c.message << "' in: " << d.str();
    EXPECT_EQ(std::string(e.what()), d.str());
  }
}

INSTANTIATE_TEST_SUITE_P(Files, BadConfigParse, ::testing::ValuesIn(cases()), case_name);

class BadConfigCheck : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadConfigCheck, edmplc_check_reports_it_and_exits_2) {
  const BadCase& c = GetParam();
  ASSERT_GT(c.line, 0) << c.path;
  // A hang is a failure ("no exit after 20 s"), not a stuck test run.
  const edm::apps::RunResult r = edm::apps::run({EDM_EDMPLC_PATH, "--check", "--config", c.path},
                                                {}, std::chrono::seconds(20));
  EXPECT_EQ(r.exit_code, 2) << r.error << r.out;  // r.out: stdout and stderr together
  const std::string where =
      c.path + ":" + std::to_string(c.line) + ":" + std::to_string(c.col) + ":";
  EXPECT_NE(r.out.find(where), std::string::npos) << "expected '" << where << "' in:\n" << r.out;
  EXPECT_NE(r.out.find(c.message), std::string::npos) << "expected '" << c.message << "' in:\n"
                                                      << r.out;
}

INSTANTIATE_TEST_SUITE_P(Files, BadConfigCheck, ::testing::ValuesIn(cases()), case_name);

}  // namespace
}  // namespace edm::rt
