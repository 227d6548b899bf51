// Seeded random mutations of a good config: the parser either accepts the text or throws a
// ConfigError whose every diagnostic is located (line >= 1) — never another exception, never a
// crash or hang. Run under EDM_SANITIZE=ON to also catch memory errors.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "edm/runtime/config.hpp"
#include "support/files.hpp"

namespace edm::rt {
namespace {

using edm::test::read_file;

// EDM_CONFIG_FUZZ_CASES=50000 for a longer local run.
int case_count(int fallback) {
  const char* env = std::getenv("EDM_CONFIG_FUZZ_CASES");
  return env != nullptr && std::atoi(env) > 0 ? std::atoi(env) : fallback;
}
constexpr std::uint64_t kSeed = 0x5eed'ed3f'00c0'ffeeULL;
const std::string kPath = "fuzz.yaml";

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    lines.push_back(l);
  }
  return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) {
    out += l;
    out += '\n';
  }
  return out;
}

// One of: delete a character, duplicate a line, swap two lines, insert a YAML-significant byte.
std::string mutate(std::string text, std::mt19937_64& rng) {
  auto pick = [&rng](std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n == 0 ? 0 : n - 1)(rng);
  };
  switch (pick(4)) {
    case 0:
      if (!text.empty()) {
        text.erase(pick(text.size()), 1);
      }
      return text;
    case 1: {
      auto lines = split_lines(text);
      const std::size_t i = pick(lines.size());
      lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
      return join_lines(lines);
    }
    case 2: {
      auto lines = split_lines(text);
      std::swap(lines[pick(lines.size())], lines[pick(lines.size())]);
      return join_lines(lines);
    }
    default: {
      static const std::string kBytes = "{}[]:,-&*!|>'\"#\t \n%@`?~.0e\xff";
      text.insert(pick(text.size() + 1), 1, kBytes[pick(kBytes.size())]);
      return text;
    }
  }
}

// Returns true if the text was rejected; records a failure if the rejection is malformed.
bool check_parse(const std::string& text, int case_no) {
  try {
    parse_config_text(text, kPath);
    return false;
  } catch (const ConfigError& e) {
    EXPECT_FALSE(e.diagnostics().empty()) << "case " << case_no;
    for (const Diagnostic& d : e.diagnostics()) {
      EXPECT_EQ(d.loc.file, kPath) << "case " << case_no;
      EXPECT_GE(d.loc.line, 1) << "case " << case_no << ": " << d.str() << "\n--- input:\n" << text;
      EXPECT_GE(d.loc.col, 1) << "case " << case_no << ": " << d.str();
      EXPECT_FALSE(d.message.empty()) << "case " << case_no;
    }
    return true;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "case " << case_no << ": unexpected " << e.what() << "\n--- input:\n" << text;
  } catch (...) {
    ADD_FAILURE() << "case " << case_no << ": unexpected non-std exception\n--- input:\n" << text;
  }
  return true;
}

TEST(ConfigFuzz, mutations_of_full_config_fail_cleanly) {
  const std::string good = read_file(std::string(EDM_TEST_DATA_DIR) + "/configs/good/full.yaml");
  ASSERT_FALSE(good.empty());
  ASSERT_NO_THROW(parse_config_text(good, kPath));
  std::mt19937_64 rng(kSeed);
  const int cases = case_count(500);
  int rejected = 0;
  for (int i = 0; i < cases; ++i) {
    std::string text = good;
    const int rounds = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < rounds; ++k) {
      text = mutate(std::move(text), rng);
    }
    rejected += check_parse(text, i) ? 1 : 0;
  }
  // Guards against a mutator that silently stopped mutating.
  EXPECT_GT(rejected, cases / 10);
  EXPECT_LT(rejected, cases);
}

TEST(ConfigFuzz, random_bytes_fail_cleanly) {
  std::mt19937_64 rng(kSeed + 1);
  const int cases = case_count(200);
  for (int i = 0; i < cases; ++i) {
    std::string text(rng() % 512, '\0');
    for (char& c : text) {
      c = static_cast<char>(rng() & 0xff);
    }
    check_parse(text, i);
  }
}

}  // namespace
}  // namespace edm::rt
