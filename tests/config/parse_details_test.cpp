// Diagnostics formatting, error collection and ordering, scalar typing, and hostile inputs.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "edm/runtime/config.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

const std::string kHead = "version: 1\nmachine: {name: m}\n";
const std::string kTasks = "tasks:\n  - {name: fast, interval: 1ms, programs: [p]}\n";

// Parses text expected to be invalid; returns its diagnostics (fails the test if it parsed).
std::vector<Diagnostic> details_errors_of(const std::string& text) {
  try {
    parse_config_text(text, "t.yaml");
  } catch (const ConfigError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << "parsed without error:\n" << text;
  return {};
}

std::string first_error(const std::string& text) {
  const auto d = details_errors_of(text);
  return d.empty() ? std::string() : d.front().str();
}

// A valid config whose program p has the given wires map body (indented by 6).
std::string with_wires(const std::string& wires) {
  return kHead + kTasks + "programs:\n  - name: p\n    blocks: [{name: b, type: T}]\n    wires:\n" +
         wires;
}

TEST(Diagnostic, str_shows_the_known_parts) {
  EXPECT_EQ((Diagnostic{{"a.yaml", 3, 7}, "bad"}).str(), "a.yaml:3:7: bad");
  EXPECT_EQ((Diagnostic{{"a.yaml", 3, 0}, "bad"}).str(), "a.yaml:3: bad");
  EXPECT_EQ((Diagnostic{{"a.yaml", 0, 0}, "bad"}).str(), "a.yaml: bad");
  EXPECT_EQ((Diagnostic{{"", 0, 0}, "bad"}).str(), "bad");
  EXPECT_EQ((Diagnostic{{"", 2, 5}, "bad"}).str(), "2:5: bad");
}

TEST(ConfigErrorTest, what_is_the_first_diagnostic) {
  const ConfigError e({{{"a.yaml", 1, 2}, "first"}, {{"a.yaml", 3, 4}, "second"}});
  EXPECT_STREQ(e.what(), "a.yaml:1:2: first");
  EXPECT_EQ(e.diagnostics().size(), 2u);
  const ConfigError empty({});
  EXPECT_STRNE(empty.what(), "");
}

TEST(ParseFile, missing_file_names_path_and_reason) {
  const std::string path = "/nonexistent/dir/edmplc.yaml";
  try {
    parse_config_file(path);
    FAIL();
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].loc.file, path);
    EXPECT_EQ(e.diagnostics()[0].loc.line, 1);
    EXPECT_EQ(std::string(e.what()), path + ":1:1: cannot open: No such file or directory");
  }
}

TEST(ParseFile, directory_is_an_error_not_an_empty_config) {
  try {
    parse_config_file(EDM_TEST_DATA_DIR);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              std::string(EDM_TEST_DATA_DIR) + ":1:1: not a regular file (a directory)");
  }
}

// Issue 17 item 10: a FIFO must not hang the check (no writer ever comes), a device must not be
// read (/dev/zero never ends), a file over the 4 MiB limit is refused unread.
TEST(ParseFile, fifo_device_and_huge_files_are_refused_at_1_1) {
  edm::test::TempDir dir;
  const std::string fifo = dir.file("machine.yaml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string huge = dir.file("huge.yaml");
  { std::ofstream(huge) << "version: 1\n"; }
  std::filesystem::resize_file(huge, std::uintmax_t{1} << 40);  // sparse: reading would not end
  const std::vector<std::pair<std::string, std::string>> cases = {
      {fifo, fifo + ":1:1: not a regular file (a FIFO)"},
      {"/dev/zero", "/dev/zero:1:1: not a regular file (a device)"},
      {huge, huge + ":1:1: config is 1099511627776 bytes; the limit is 4 MiB"},
  };
  for (const auto& [path, message] : cases) {
    try {
      parse_config_file(path);
      ADD_FAILURE() << path << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
  try {
    parse_config_text(std::string((std::size_t{4} << 20) + 1, '#'), "big.yaml");
    ADD_FAILURE() << "a 4 MiB + 1 text accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("big.yaml:1:1: config is 4194305 bytes"),
              std::string::npos)
        << e.what();
  }
}

TEST(Collect, several_errors_reported_in_file_order) {
  const auto d = details_errors_of(
      "version: 1\n"
      "machine: {name: m, colour: red}\n"  // 2: unknown key
      "tasks:\n"
      "  - {name: fast, interval: 1ms, priority: 99, programs: [p, q]}\n"  // 4: range, unknown q
      "programs:\n"
      "  - name: p\n"
      "    blocks: [{name: a, type: T}, {name: a, type: T}]\n"  // 7: duplicate block
      "bridge: {port: -1}\n");                                  // 8: range
  ASSERT_EQ(d.size(), 5u);
  EXPECT_EQ(d[0].loc.line, 2);
  EXPECT_NE(d[0].message.find("unknown key 'colour'"), std::string::npos);
  EXPECT_EQ(d[1].loc.line, 4);
  EXPECT_NE(d[1].message.find("priority"), std::string::npos);
  EXPECT_EQ(d[2].loc.line, 4);
  EXPECT_NE(d[2].message.find("unknown program 'q'"), std::string::npos);
  EXPECT_LT(d[1].loc.col, d[2].loc.col);
  EXPECT_EQ(d[3].loc.line, 7);
  EXPECT_EQ(d[4].loc.line, 8);
}

TEST(Collect, misspelt_required_key_is_one_error_not_two) {
  const auto d = details_errors_of(
      kHead + "tasks:\n  - {name: f, intervall: 1ms, programs: [p]}\n" + "programs: [{name: p}]\n");
  ASSERT_EQ(d.size(), 1u) << d[1].str();
  EXPECT_NE(d[0].message.find("did you mean 'interval'"), std::string::npos);
}

TEST(Collect, unrelated_unknown_key_gets_no_suggestion) {
  const std::string e = first_error(kHead + kTasks + "programs: [{name: p}]\nzzzzzz: 1\n");
  EXPECT_EQ(e.find("did you mean"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed keys: version, machine"), std::string::npos) << e;
}

TEST(Collect, error_flood_is_capped) {
  std::string text = kHead + kTasks + "programs: [{name: p}]\nbridge:\n";
  for (int i = 0; i < 300; ++i) {
    text += "  k" + std::to_string(i) + ": 1\n";
  }
  const auto d = details_errors_of(text);
  ASSERT_EQ(d.size(), 101u);
  EXPECT_NE(d.back().message.find("200 more errors"), std::string::npos) << d.back().str();
  EXPECT_GE(d.back().loc.line, 1);
}

TEST(Scalars, integers_are_strict) {
  const auto priority = [](const std::string& v) {
    return first_error(kHead + "tasks:\n  - {name: f, interval: 1ms, priority: " + v +
                       ", programs: [p]}\nprograms: [{name: p}]\n");
  };
  EXPECT_NE(priority("99999999999999999999999").find("must be in 0..31"), std::string::npos);
  EXPECT_NE(priority("1e3").find("expected an integer"), std::string::npos);
  EXPECT_NE(priority("true").find("expected an integer"), std::string::npos);
  EXPECT_NE(priority("0x1").find("expected an integer"), std::string::npos);
  EXPECT_NE(priority("[1]").find("expected an integer, got a list"), std::string::npos);
  EXPECT_NE(priority("!!int 3").find("tag"), std::string::npos);
}

TEST(Scalars, reals_accept_ints_and_reject_non_finite) {
  const auto voltage = [](const std::string& v) {
    return kHead + kTasks + "programs: [{name: p}]\nconditions: [{E: 1, open_voltage_v: " + v +
           "}]\n";
  };
  EXPECT_DOUBLE_EQ(parse_config_text(voltage("+80"), "t").conditions[0].open_voltage_v, 80.0);
  EXPECT_DOUBLE_EQ(parse_config_text(voltage("1.5e2"), "t").conditions[0].open_voltage_v, 150.0);
  EXPECT_DOUBLE_EQ(parse_config_text(voltage(".5"), "t").conditions[0].open_voltage_v, 0.5);
  EXPECT_NE(first_error(voltage(".inf")).find("finite"), std::string::npos);
  EXPECT_NE(first_error(voltage("-.Inf")).find("finite"), std::string::npos);
  EXPECT_NE(first_error(voltage(".NaN")).find("finite"), std::string::npos);
  EXPECT_NE(first_error(voltage("1e999")).find("out of range"), std::string::npos);
  EXPECT_NE(first_error(voltage("\"80\"")).find("expected a number, got the string"),
            std::string::npos);
  EXPECT_NE(first_error(voltage("0")).find("must be > 0"), std::string::npos);
}

TEST(Scalars, durations_need_units) {
  const auto interval = [](const std::string& v) {
    return kHead + "tasks:\n  - {name: f, interval: " + v +
           ", programs: [p]}\nprograms: [{name: p}]\n";
  };
  EXPECT_EQ(parse_config_text(interval("1.5ms"), "t").tasks[0].interval,
            std::chrono::microseconds(1500));
  EXPECT_EQ(parse_config_text(interval("\"2s\""), "t").tasks[0].interval, std::chrono::seconds(2));
  EXPECT_NE(first_error(interval("1.5")).find("duration needs a unit, e.g. 1ms"),
            std::string::npos);
  EXPECT_NE(first_error(interval("1 fortnight")).find("not a duration"), std::string::npos);
  EXPECT_NE(first_error(interval(".inf")).find("not a duration"), std::string::npos);
}

TEST(Wires, constants_names_and_rejects) {
  const Config cfg = parse_config_text(
      with_wires("      b.a: -3\n      b.b: 1e3\n      b.c: false\n      b.d: \"io.x\"\n"
                 "      io.y: other.b.out\n"),
      "t");
  const auto& w = cfg.programs[0].wires;
  ASSERT_EQ(w.size(), 5u);
  EXPECT_FALSE(w[0].source_is_name);
  EXPECT_EQ(w[0].source, "-3");
  EXPECT_FALSE(w[1].source_is_name);
  EXPECT_FALSE(w[2].source_is_name);
  EXPECT_TRUE(w[3].source_is_name);  // a quoted name is still a name
  EXPECT_EQ(w[3].source, "io.x");
  EXPECT_TRUE(w[4].source_is_name);
  EXPECT_EQ(w[4].dest, "io.y");

  EXPECT_NE(first_error(with_wires("      b.a: yes\n")).find("source 'yes'"), std::string::npos);
  EXPECT_NE(first_error(with_wires("      b.a: \"1.0\"\n")).find("source '1.0'"),
            std::string::npos);
  EXPECT_NE(first_error(with_wires("      b.a: .nan\n")).find("finite"), std::string::npos);
  EXPECT_NE(first_error(with_wires("      b.a: 1e999\n")).find("out of range"), std::string::npos);
  EXPECT_NE(first_error(with_wires("      b.a: a.b.c.d.e.f\n")).find("source"), std::string::npos);
  EXPECT_NE(first_error(with_wires("      b.a:\n")).find("got nothing"), std::string::npos);
  EXPECT_NE(first_error(with_wires("      a.b.c.d.e: x.y\n")).find("destination 'a.b.c.d.e'"),
            std::string::npos);
  EXPECT_NE(first_error(with_wires("      [a]: x.y\n")).find("keys must be plain strings"),
            std::string::npos);
}

TEST(Hostile, alias_bomb_is_not_expanded) {
  // Aliases share nodes in yaml-cpp; nothing here may walk them recursively.
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 30; ++i) {
    const std::string p = "*a" + std::to_string(i - 1);
    text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + p + ", " + p + ", " + p +
            ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + "]\n";
  }
  const auto start = std::chrono::steady_clock::now();
  const auto d = details_errors_of(text);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  ASSERT_FALSE(d.empty());
}

TEST(Hostile, self_referencing_alias_in_every_section) {
  for (const char* section : {"machine", "conditions", "tasks", "programs", "trace", "bridge"}) {
    const std::string text = kHead + kTasks + "programs: [{name: p}]\n" + "x: &r {" + section +
                             ": *r}\n" + std::string(section) + ": &s [*s, {a: *s}]\n";
    const auto d = details_errors_of(text);
    EXPECT_FALSE(d.empty()) << section;
  }
  const std::string params = kHead + kTasks +
                             "programs: [{name: p, blocks: [{name: b, type: T, params: &m "
                             "{k: *m}}], wires: &w {b.x: *w}}]\n";
  EXPECT_EQ(details_errors_of(params).size(), 2u);
}

TEST(Hostile, deep_nesting_is_an_error_not_a_stack_overflow) {
  std::string block = "version: 1\nmachine:\n";
  for (int i = 0; i < 5000; ++i) {
    block += std::string(static_cast<std::size_t>(i % 200 + 1), ' ') + "- \n";
  }
  EXPECT_FALSE(details_errors_of(block).empty());
  EXPECT_NE(first_error(kHead + "tasks: " + std::string(100000, '[')).find("t.yaml:"),
            std::string::npos);
  EXPECT_NE(first_error(kHead + "tasks: " + std::string(100000, '{')).find("t.yaml:"),
            std::string::npos);
}

TEST(Hostile, encodings_and_line_endings) {
  std::string crlf = kHead + kTasks + "programs: [{name: p}]\n";
  for (std::size_t i = 0; (i = crlf.find('\n', i)) != std::string::npos; i += 2) {
    crlf.insert(i, "\r");
  }
  EXPECT_EQ(parse_config_text(crlf, "t").tasks[0].name, "fast");
  EXPECT_EQ(parse_config_text("\xEF\xBB\xBF" + kHead + kTasks + "programs: [{name: p}]\n", "t")
                .machine.name,
            "m");
  // Invalid UTF-8 in a free-form string is kept as written; in an identifier it is an error.
  EXPECT_EQ(
      parse_config_text(
          "version: 1\nmachine: {name: \"m\xff\"}\n" + kTasks + "programs: [{name: p}]\n", "t")
          .machine.name,
      "m\xff");
  EXPECT_FALSE(details_errors_of(kHead +
                                 "tasks: [{name: \"f\xc3\", interval: 1ms, programs: [p]}]\n" +
                                 "programs: [{name: p}]\n")
                   .empty());
  EXPECT_FALSE(details_errors_of(std::string("version: 1\0machine: x\n", 22)).empty());
}

TEST(Hostile, null_sections_say_how_to_write_empty) {
  const std::string e = first_error(kHead + kTasks + "programs: [{name: p}]\nconditions:\n");
  EXPECT_NE(e.find("t.yaml:6:1: conditions: expected a list, got nothing (null)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("write []"), std::string::npos) << e;
}

}  // namespace
}  // namespace edm::rt

namespace edm::rt {
namespace {

// The bridge keys added with the server (issue 5): parsed with units, ranges checked with
// file:line:col.
TEST(BridgeKeys, timeouts_queue_and_status_vars_parse) {
  const Config cfg =
      parse_config_text(kHead + kTasks +
                            "programs: [{name: p}]\n"
                            "bridge: {read_timeout: 30s, stall_timeout: 750ms, queue_limit: 64,\n"
                            "         status_vars: [io.z_mm, p.b.out]}\n",
                        "t.yaml");
  EXPECT_EQ(cfg.bridge.read_timeout, std::chrono::seconds(30));
  EXPECT_EQ(cfg.bridge.stall_timeout, std::chrono::milliseconds(750));
  EXPECT_EQ(cfg.bridge.queue_limit, 64u);
  ASSERT_EQ(cfg.bridge.status_vars.size(), 2u);
  EXPECT_EQ(cfg.bridge.status_vars[1].name, "p.b.out");
}

TEST(BridgeKeys, out_of_range_values_name_their_position) {
  EXPECT_EQ(first_error(kHead + kTasks + "programs: [{name: p}]\nbridge: {queue_limit: 2}\n"),
            "t.yaml:6:23: bridge.queue_limit: must be in 16..65536 (got 2)");
  const std::string e =
      first_error(kHead + kTasks + "programs: [{name: p}]\nbridge: {read_timeout: 1ms}\n");
  EXPECT_EQ(e.rfind("t.yaml:6:24: ", 0), 0u) << e;
  EXPECT_NE(e.find("read_timeout must be between 100ms and 24h"), std::string::npos) << e;
}

}  // namespace
}  // namespace edm::rt
