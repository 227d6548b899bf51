// The one op table (issue 32, item 4) against what docs/protocol.md promises clients: an op the
// protocol lists must have a row, and so a handler (a row cannot be without one: op_table.cpp
// does not compile then); an op with a row must be listed, with the roles and states the page
// gives. Then through a real server: every row is dispatched, nothing else is.
#include "edm/bridge/op_table.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "bridge_fixture.hpp"

namespace edm::bridge::test {
namespace {

constexpr StateMask kEveryState = (1U << kOpStateCount) - 1;

std::string read_protocol_page() {
  std::ifstream in(std::string(EDM_SOURCE_DIR) + "/docs/protocol.md");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The text of section `heading` ("## Ops"): up to the next heading of the same level.
std::string section(const std::string& page, const std::string& heading) {
  const auto at = page.find("\n" + heading + "\n");
  if (at == std::string::npos) return "";
  const auto body = at + heading.size() + 2;
  const auto end = page.find("\n## ", body);
  return page.substr(body, end == std::string::npos ? std::string::npos : end - body);
}

/// Every `code span` of `text`, in order.
std::vector<std::string> code_spans(const std::string& text) {
  std::vector<std::string> out;
  static const std::regex span("`([^`]+)`");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), span); it != std::sregex_iterator();
       ++it) {
    out.push_back((*it)[1]);
  }
  return out;
}

std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// A state as the page names it ("READY idle", "RUNNING", …).
StateMask state_named(std::string name) {
  while (!name.empty() && name.back() == ' ') name.pop_back();
  while (!name.empty() && name.front() == ' ') name.erase(0, 1);
  static const std::map<std::string, OpState> kNames = {
      {"OFF", OpState::kOff},
      {"READY idle", OpState::kIdle},
      {"READY with a continuous jog", OpState::kJogging},
      {"READY with another manual operation", OpState::kManual},
      {"RUNNING", OpState::kRunning},
      {"HOLD", OpState::kHold},
      {"FAULT", OpState::kFault},
      {"ESTOP", OpState::kEstop}};
  const auto it = kNames.find(name);
  EXPECT_NE(it, kNames.end()) << "docs/protocol.md names a state '" << name << "'";
  return it == kNames.end() ? 0 : mask_of(it->second);
}

/// "every state", "every state but RUNNING and HOLD", "RUNNING, HOLD", "READY idle, READY with
/// a continuous jog (its refresh, …)".
StateMask states_named(std::string cell) {
  cell = std::regex_replace(cell, std::regex(R"(\s*\([^)]*\))"), "");
  StateMask m = 0;
  bool but = false;
  if (cell.rfind("every state", 0) == 0) {
    m = kEveryState;
    cell.erase(0, std::string("every state").size());
    if (cell.rfind(" but ", 0) == 0) {
      but = true;
      cell.erase(0, 5);
    }
    if (!but) return m;
  }
  cell = std::regex_replace(cell, std::regex(" and "), ", ");
  std::size_t from = 0;
  while (from <= cell.size()) {
    const auto comma = cell.find(", ", from);
    const StateMask s = state_named(cell.substr(from, comma - from));
    m = but ? static_cast<StateMask>(m & ~s) : static_cast<StateMask>(m | s);
    if (comma == std::string::npos) break;
    from = comma + 2;
  }
  return m;
}

/// The "Op states" table: (op, kind) → states. jog's rows are "`jog` with `distance`".
std::map<std::pair<std::string, std::string>, StateMask> documented_states(
    const std::string& page) {
  std::map<std::pair<std::string, std::string>, StateMask> out;
  std::istringstream in(section(page, "## Op states"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `", 0) != 0) continue;  // the header, its rule and the prose
    const auto bar = line.find(" | ", 2);
    const std::string ops = line.substr(2, bar - 2);
    const StateMask states = states_named(line.substr(bar + 3, line.size() - bar - 5));
    std::size_t from = 0;
    while (from < ops.size()) {
      const auto comma = ops.find(", ", from);
      const std::string item = ops.substr(from, comma - from);
      const auto spans = code_spans(item);
      if (item.find(" with ") != std::string::npos && spans.size() == 2) {
        EXPECT_TRUE(out.emplace(std::pair{spans[0], spans[1]}, states).second) << item;
      } else {
        for (const auto& span : spans) {
          for (const auto& op : words(span)) {
            EXPECT_TRUE(out.emplace(std::pair{op, std::string()}, states).second)
                << op << " is listed twice";
          }
        }
      }
      if (comma == std::string::npos) break;
      from = comma + 2;
    }
  }
  return out;
}

std::set<std::string> table_names() {
  std::set<std::string> names;
  for (const OpSpec& op : op_table()) names.insert(std::string(op.name));
  return names;
}

TEST(OpTable, every_op_the_protocol_lists_has_a_row_and_every_row_is_listed) {
  const std::string page = read_protocol_page();
  ASSERT_FALSE(page.empty()) << "docs/protocol.md not found";
  std::set<std::string> listed;
  for (const auto& [key, states] : documented_states(page)) listed.insert(key.first);
  std::set<std::string> sections;
  std::istringstream in(section(page, "## Ops"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("### ", 0) != 0) continue;
    for (const auto& span : code_spans(line)) sections.insert(span);
  }
  ASSERT_GT(listed.size(), 20u) << "the Op states table was not read";
  const std::set<std::string> rows = table_names();
  for (const auto& op : listed) {
    EXPECT_TRUE(rows.count(op)) << op << ": listed in docs/protocol.md, but no row (no handler)";
  }
  for (const auto& op : sections) {
    EXPECT_TRUE(rows.count(op)) << op << ": a docs/protocol.md section, but no row (no handler)";
  }
  for (const OpSpec& op : op_table()) {
    const std::string name(op.name);
    EXPECT_NE(op.handler, nullptr) << name;
    EXPECT_TRUE(listed.count(name)) << name << ": handled, but not in the Op states table";
    // hello has its place under "Authentication and roles", the others a section under "Ops".
    if (op.access != OpAccess::kBeforeHello) {
      EXPECT_TRUE(sections.count(name)) << name << ": handled, but no section under ## Ops";
    }
  }
  EXPECT_EQ(rows.size(), op_table().size()) << "a name in two rows";
}

TEST(OpTable, the_roles_are_the_ones_the_protocol_gives) {
  // "`viewer`: read-only ops — `hello ping …`": the ops a viewer may run; an operator runs all.
  std::string auth = section(read_protocol_page(), "## Authentication and roles");
  auth = std::regex_replace(auth, std::regex(R"(\s+)"), " ");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(auth, m, std::regex("read-only ops — `([^`]+)`"))) << auth;
  std::set<std::string> viewer_ops;
  for (const auto& w : words(m[1])) viewer_ops.insert(w);
  std::set<std::string> viewer_rows;
  for (const OpSpec& op : op_table()) {
    if (op.access != OpAccess::kOperator) viewer_rows.insert(std::string(op.name));
  }
  EXPECT_EQ(viewer_rows, viewer_ops);
  const OpSpec* hello = find_op("hello");
  ASSERT_NE(hello, nullptr);
  EXPECT_EQ(hello->access, OpAccess::kBeforeHello) << "the first request must be hello";
  for (const OpSpec& op : op_table()) {
    EXPECT_EQ(op.access == OpAccess::kBeforeHello, &op == hello) << op.name;
  }
}

TEST(OpTable, the_states_are_the_ones_the_protocol_gives) {
  const auto documented = documented_states(read_protocol_page());
  std::size_t kinds = 0;
  for (const OpSpec& op : op_table()) {
    std::vector<const OpKind*> ks{&op.kind};
    if (!op.kind_field.empty()) ks.push_back(&op.field_kind);
    for (const OpKind* k : ks) {
      ++kinds;
      const auto it = documented.find({std::string(op.name), std::string(k->name)});
      ASSERT_NE(it, documented.end()) << op.name << " " << k->name << ": no row in Op states";
      EXPECT_EQ(it->second, k->allowed) << op.name << " " << k->name;
    }
  }
  EXPECT_EQ(documented.size(), kinds) << "an (op, kind) in docs that the table does not have";
}

class OpTableServer : public BridgeFixture {};

TEST_F(OpTableServer, every_row_is_dispatched_and_nothing_else) {
  start();
  Client c;
  ASSERT_EQ(c.connect(client_opts()), Role::kOperator);
  const Reply info = c.request("machine.info");
  ASSERT_TRUE(info) << info.message;
  std::set<std::string> advertised;
  for (const auto& op : info.body.at("ops")) advertised.insert(op.get<std::string>());
  EXPECT_EQ(advertised, table_names()) << "machine.info's ops are the table";
  for (const OpSpec& op : op_table()) {
    const Reply r = c.request(op.name, Json::object());
    EXPECT_TRUE(r.ok || r.code != ErrorCode::kUnknownOp) << op.name << ": " << r.message;
  }
  for (const char* name : {"format.disk", "Status", "status ", "cycle", ""}) {
    expect_error(c.request(name), ErrorCode::kUnknownOp);
    EXPECT_EQ(find_op(name), nullptr) << name;
  }
}

}  // namespace
}  // namespace edm::bridge::test
