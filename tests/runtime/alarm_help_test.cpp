// Every alarm code has a cause and a remedy for the operator (issue 33, "alarms that say why"),
// and docs/safety.md "Alarm codes" lists each code with the same texts: the page, edmhmi and
// the manual cannot drift apart.
#include "edm/runtime/alarm_help.hpp"

#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>
#include <string>

#include "support/files.hpp"

namespace edm::test {
namespace {

struct DocRow {
  std::string name, cause, remedy;
};

// The rows of the "## Alarm codes" table: | code | `name` | cause | remedy |.
std::map<int, DocRow> doc_rows() {
  const std::string doc = read_file(std::string(EDM_SOURCE_DIR) + "/docs/safety.md");
  const auto at = doc.find("## Alarm codes");
  EXPECT_NE(at, std::string::npos) << "docs/safety.md has no 'Alarm codes' section";
  const auto end = doc.find("\n## ", at + 1);
  const std::string section = doc.substr(at, end == std::string::npos ? end : end - at);
  std::map<int, DocRow> rows;
  const std::regex row(R"(\n\| (\d+) \| `(\w+)` \| ([^|]+) \| ([^|]+) \|)");
  for (std::sregex_iterator it(section.begin(), section.end(), row), e; it != e; ++it) {
    rows[std::stoi((*it)[1])] = {(*it)[2], (*it)[3], (*it)[4]};
  }
  return rows;
}

TEST(AlarmHelp, EveryCodeHasACauseAndARemedyAndIsInTheManual) {
  const std::map<int, DocRow> rows = doc_rows();
  std::set<int> codes;
  for (const rt::AlarmCode c : rt::all_alarm_codes()) {
    const int code = static_cast<int>(c);
    codes.insert(code);
    const rt::AlarmHelp h = rt::alarm_help(c);
    EXPECT_GE(h.cause.size(), 10u) << code;
    EXPECT_GE(h.remedy.size(), 10u) << code;
    EXPECT_NE(rt::to_string(c), "?") << code;
    const auto row = rows.find(code);
    ASSERT_NE(row, rows.end()) << "docs/safety.md lacks alarm " << code;
    EXPECT_EQ(row->second.name, rt::to_string(c)) << code;
    EXPECT_EQ(row->second.cause, h.cause) << code;
    EXPECT_EQ(row->second.remedy, h.remedy) << code;
  }
  for (const auto& [code, row] : rows) {
    EXPECT_TRUE(codes.contains(code)) << "docs/safety.md lists " << code << " (" << row.name
                                      << "), which the runtime does not raise";
  }
  EXPECT_EQ(rows.size(), codes.size());
  EXPECT_TRUE(rt::alarm_help(rt::AlarmCode::kNone).cause.empty());
}

// The list is the enum's: every value between the lowest and highest code that has a name.
TEST(AlarmHelp, TheListHoldsEveryNamedCodeInOrder) {
  int last = 0;
  std::size_t named = 0;
  for (int v = 1; v < 1000; ++v) {
    if (rt::to_string(static_cast<rt::AlarmCode>(v)) != "?") ++named;
  }
  for (const rt::AlarmCode c : rt::all_alarm_codes()) {
    EXPECT_GT(static_cast<int>(c), last);
    last = static_cast<int>(c);
  }
  EXPECT_EQ(rt::all_alarm_codes().size(), named);
}

}  // namespace
}  // namespace edm::test
