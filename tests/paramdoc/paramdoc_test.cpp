// The parameter-table generator (apps/paramdoc): how a ParamSpec is rendered, and the splicing of
// generated tables between marker lines.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "doc_markers.hpp"
#include "edm/runtime/block.hpp"
#include "param_table.hpp"

namespace {

using edm::paramdoc::param_table;
using edm::paramdoc::splice_tables;
using namespace std::chrono_literals;

struct SampleParams {
  double kg{0.05};
  double big{-1e9};
  std::int64_t window{8};
  edm::rt::Duration settle{20ms};
  edm::rt::Duration ramp{0};
  bool hold{true};
  std::string terms{"a | b"};

  void visit(edm::rt::ParamVisitor& v) {
    v.param("kg", kg, {.unit = "mm/s/us", .description = "gain", .range = edm::rt::kPositive});
    v.param("big", big, {.description = "lower | limit"});
    v.param("window", window,
            {.unit = "cycles", .range = edm::rt::closed(1, 64), .load_time_only = true});
    v.param("settle", settle, {.unit = "s", .range = edm::rt::closed(0.001, 1)});
    v.param("ramp", ramp, {.unit = "s", .range = edm::rt::kNonNegative});
    v.param("hold", hold);
    v.param("terms", terms);
  }
};

class Sample final : public edm::rt::BlockWithParams<SampleParams> {
 public:
  void visit_pins(edm::rt::PinVisitor& /*v*/) override {}
  edm::rt::BlockStatus update(const edm::rt::CycleContext& /*ctx*/) noexcept override {
    return edm::rt::BlockStatus::kOk;
  }
};

class Empty final : public edm::rt::Block {
 public:
  void visit_pins(edm::rt::PinVisitor& /*v*/) override {}
  edm::rt::BlockStatus update(const edm::rt::CycleContext& /*ctx*/) noexcept override {
    return edm::rt::BlockStatus::kOk;
  }
};

TEST(ParamTable, renders_each_field_as_the_yaml_would_write_it) {
  Sample b;
  EXPECT_EQ(param_table(b),
            "| parameter | type | unit | range | default | run-time writable | description |\n"
            "|---|---|---|---|---|---|---|\n"
            "| `kg` | LREAL | mm/s/us | > 0, finite | `0.05` | yes | gain |\n"
            "| `big` | LREAL |  | finite | `-1e9` | yes | lower \\| limit |\n"
            "| `window` | LINT | cycles | [1, 64] | `8` | no |  |\n"
            "| `settle` | TIME | s | [0.001, 1] s | `20ms` | yes |  |\n"
            "| `ramp` | TIME | s | >= 0 | `0s` | yes |  |\n"
            "| `hold` | BOOL |  |  | `true` | yes |  |\n"
            "| `terms` | STRING |  |  | `a \\| b` | no |  |\n");
}

TEST(ParamTable, says_so_for_a_type_without_parameters) {
  Empty b;
  EXPECT_EQ(param_table(b), "No parameters.\n");
}

const std::map<std::string, std::string> kWanted{{"A", "new A\n"}, {"B", "B\n"}};

TEST(SpliceTables, replaces_the_body_between_the_markers_and_names_what_changed) {
  const auto r = splice_tables(
      "intro\n<!-- params:A -->\nold A\n<!-- /params:A -->\nmid\n<!-- params:B -->\nB\n"
      "<!-- /params:B -->\nend\n",
      kWanted);
  EXPECT_EQ(r.text,
            "intro\n<!-- params:A -->\nnew A\n<!-- /params:A -->\nmid\n<!-- params:B -->\nB\n"
            "<!-- /params:B -->\nend\n");
  EXPECT_EQ(r.found, (std::vector<std::string>{"A", "B"}));
  EXPECT_EQ(r.stale, (std::vector<std::string>{"A"}));
  EXPECT_TRUE(r.errors.empty());
}

TEST(SpliceTables, an_up_to_date_file_comes_back_unchanged) {
  const std::string text = "<!-- params:A -->\nnew A\n<!-- /params:A -->\n";
  const auto r = splice_tables(text, kWanted);
  EXPECT_EQ(r.text, text);
  EXPECT_TRUE(r.stale.empty());
  EXPECT_TRUE(r.errors.empty());
}

TEST(SpliceTables, an_unknown_type_is_an_error_and_its_section_is_kept) {
  const std::string text = "<!-- params:Nope -->\nhand\n<!-- /params:Nope -->\n";
  const auto r = splice_tables(text, kWanted);
  EXPECT_EQ(r.text, text);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0], "line 1: no registered block or driver type 'Nope'");
}

TEST(SpliceTables, unclosed_orphaned_and_repeated_markers_are_errors_with_their_line) {
  const auto r = splice_tables(
      "<!-- params:A -->\nx\n<!-- params:B -->\n<!-- /params:B -->\n<!-- /params:A -->\n"
      "<!-- params:B -->\n<!-- /params:B -->\n",
      kWanted);
  ASSERT_EQ(r.errors.size(), 3u);
  EXPECT_EQ(r.errors[0].rfind("line 1: 'A' has no closing marker", 0), 0u);
  EXPECT_EQ(r.errors[1], "line 5: closing marker for 'A' without its opening one");
  EXPECT_EQ(r.errors[2], "line 6: a second section for 'B'");
}

}  // namespace
