#include "edm/runtime/stats_json.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace edm::rt {
namespace {

using std::chrono::microseconds;

// A strict JSON grammar checker (RFC 8259, no extensions): the test target has no JSON library,
// and brace counting alone would accept e.g. a missing comma or an unescaped quote.
class JsonChecker {
 public:
  explicit JsonChecker(std::string_view text) : text_(text) {}
  bool valid() {
    skip_ws();
    if (!value()) {
      return false;
    }
    skip_ws();
    return pos_ == text_.size();
  }

 private:
  bool value() {
    skip_ws();
    if (pos_ >= text_.size()) {
      return false;
    }
    switch (text_[pos_]) {
      case '{': return object();
      case '[': return array();
      case '"': return string();
      case 't': return literal("true");
      case 'f': return literal("false");
      case 'n': return literal("null");
      default: return number();
    }
  }
  bool object() {
    ++pos_;
    skip_ws();
    if (eat('}')) {
      return true;
    }
    do {
      skip_ws();
      if (!string()) {
        return false;
      }
      skip_ws();
      if (!eat(':') || !value()) {
        return false;
      }
      skip_ws();
    } while (eat(','));
    return eat('}');
  }
  bool array() {
    ++pos_;
    skip_ws();
    if (eat(']')) {
      return true;
    }
    do {
      if (!value()) {
        return false;
      }
      skip_ws();
    } while (eat(','));
    return eat(']');
  }
  bool string() {
    if (!eat('"')) {
      return false;
    }
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') {
        return true;
      }
      if (static_cast<unsigned char>(c) < 0x20) {
        return false;  // raw control characters must be escaped
      }
      if (c == '\\') {
        if (pos_ >= text_.size()) {
          return false;
        }
        const char e = text_[pos_++];
        if (e == 'u') {
          for (int i = 0; i < 4; ++i) {
            if (pos_ >= text_.size() || !std::isxdigit(static_cast<unsigned char>(text_[pos_++]))) {
              return false;
            }
          }
        } else if (std::string_view("\"\\/bfnrt").find(e) == std::string_view::npos) {
          return false;
        }
      }
    }
    return false;
  }
  bool number() {
    const std::size_t start = pos_;
    eat('-');
    if (!eat('0') && !digits()) {  // no leading zeros
      return false;
    }
    if (eat('.') && !digits()) {
      return false;
    }
    if (eat('e') || eat('E')) {
      if (!eat('+')) {
        eat('-');
      }
      if (!digits()) {
        return false;
      }
    }
    return pos_ > start;
  }
  bool digits() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_]))) {
      ++pos_;
    }
    return pos_ > start;
  }
  bool literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) {
      return false;
    }
    pos_ += word.size();
    return true;
  }
  bool eat(char c) {
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void skip_ws() {
    while (pos_ < text_.size() &&
           std::string_view(" \t\r\n").find(text_[pos_]) != std::string_view::npos) {
      ++pos_;
    }
  }

  std::string_view text_;
  std::size_t pos_{0};
};

bool brackets_balance(std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      ++depth;
    } else if (c == '}' || c == ']') {
      if (--depth < 0) {
        return false;
      }
    }
  }
  return depth == 0 && !in_string;
}

TaskStatsReport sample_task() {
  TaskStatsReport t;
  t.name = "gap";
  t.interval = microseconds(250);
  t.priority = 2;
  t.stats.cycles = 4000;
  t.stats.overruns = 3;
  t.stats.omitted_cycles = 5;
  t.stats.exec = {12.0, 14.5, 14.1234, 20.0006, 31.25};
  t.stats.latency = {1.0, 2.5, 2.25, 9.9999, 12.0};
  return t;
}

TEST(StatsJson, golden_single_task) {
  // nlohmann_json prints each value rounded to 3 decimals in its shortest form (250.0, 31.25).
  const std::string expected = R"({
  "tasks": [
    {
      "name": "gap",
      "interval_us": 250.0,
      "priority": 2,
      "cycles": 4000,
      "overruns": 3,
      "omitted_cycles": 5,
      "exec_us": {
        "min": 12.0,
        "avg": 14.5,
        "p50": 14.123,
        "p99": 20.001,
        "max": 31.25
      },
      "latency_us": {
        "min": 1.0,
        "avg": 2.5,
        "p50": 2.25,
        "p99": 10.0,
        "max": 12.0
      }
    }
  ]
}
)";
  const std::string json = stats_to_json({sample_task()});
  EXPECT_EQ(json, expected);
  EXPECT_TRUE(JsonChecker(json).valid());
}

TEST(StatsJson, no_tasks_is_an_empty_array) {
  const std::string json = stats_to_json({});
  EXPECT_EQ(json, "{\n  \"tasks\": []\n}\n");
  EXPECT_TRUE(JsonChecker(json).valid());
}

TEST(StatsJson, several_tasks_in_order_and_valid) {
  TaskStatsReport slow = sample_task();
  slow.name = "slow";
  slow.interval = std::chrono::milliseconds(40);
  const std::string json = stats_to_json({sample_task(), slow});
  EXPECT_TRUE(JsonChecker(json).valid()) << json;
  EXPECT_TRUE(brackets_balance(json));
  const std::size_t gap = json.find("\"name\": \"gap\"");
  const std::size_t slow_at = json.find("\"name\": \"slow\"");
  ASSERT_NE(gap, std::string::npos);
  ASSERT_NE(slow_at, std::string::npos);
  EXPECT_LT(gap, slow_at);
  EXPECT_NE(json.find("\"interval_us\": 40000.0,"), std::string::npos);
  for (const char* key :
       {"\"interval_us\"", "\"priority\"", "\"cycles\"", "\"overruns\"", "\"omitted_cycles\"",
        "\"exec_us\"", "\"latency_us\"", "\"min\"", "\"avg\"", "\"p50\"", "\"p99\"", "\"max\""}) {
    std::size_t count = 0;
    for (std::size_t at = json.find(key); at != std::string::npos; at = json.find(key, at + 1)) {
      ++count;
    }
    const std::size_t per_task = std::string_view(key).size() == 5 ? 2 : 1;  // summary keys
    EXPECT_EQ(count, 2 * per_task) << key;
  }
}

TEST(StatsJson, names_are_escaped) {
  TaskStatsReport t = sample_task();
  t.name = std::string("a\"b\\c\nd\te\x01\x1f/\xc3\xa9");
  const std::string json = stats_to_json({t});
  EXPECT_NE(json.find(R"("name": "a\"b\\c\nd\te\u0001\u001f/)"
                      "\xc3\xa9\""),
            std::string::npos)
      << json;
  EXPECT_TRUE(JsonChecker(json).valid()) << json;
  EXPECT_TRUE(brackets_balance(json));

  // Invalid UTF-8 cannot make the document invalid: it becomes U+FFFD.
  t.name = "a\xff";
  const std::string replaced = stats_to_json({t});
  EXPECT_NE(replaced.find("\"name\": \"a\xef\xbf\xbd\""), std::string::npos) << replaced;

  // Brackets and braces inside a name must not look like structure.
  t.name = "}]{[\"";
  const std::string tricky = stats_to_json({t});
  EXPECT_TRUE(JsonChecker(tricky).valid()) << tricky;
  EXPECT_TRUE(brackets_balance(tricky));
}

TEST(StatsJson, checker_rejects_broken_documents) {
  // The checks above would be worthless if the checker accepted anything.
  EXPECT_FALSE(JsonChecker(R"({"a": "b"c"})").valid());
  EXPECT_FALSE(JsonChecker(R"({"a": 1 "b": 2})").valid());
  EXPECT_FALSE(JsonChecker("{\"a\": \"x\ny\"}").valid());
  EXPECT_FALSE(JsonChecker(R"({"a": [1, 2})").valid());
  EXPECT_FALSE(brackets_balance(R"({"a": [1, 2})"));
  EXPECT_TRUE(JsonChecker(R"({"a": [1.5, -2e3, "\u00e9"], "b": {}})").valid());
}

TEST(StatsJson, writes_file) {
  // Per-process name: parallel ctest runs of this test must not share the file.
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("edm_stats_json_test_" + std::to_string(::getpid()) + ".json");
  const std::vector<TaskStatsReport> tasks{sample_task()};
  write_stats_json_file(path.string(), tasks);
  std::ifstream in(path, std::ios::binary);
  std::stringstream content;
  content << in.rdbuf();
  EXPECT_EQ(content.str(), stats_to_json(tasks));
  std::filesystem::remove(path);
}

TEST(StatsJson, write_failure_names_path_and_reason) {
  const std::string path = "/nonexistent-edm-dir/sub/stats.json";
  try {
    write_stats_json_file(path, {sample_task()});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace edm::rt
