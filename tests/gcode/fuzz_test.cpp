// Seeded random input: the interpreter never crashes or hangs, and its answer is always either
// blocks (well-formed, inside the soft limits) or located errors, never both.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

void check_answer(const std::string& text, const GcodeResult& r) {
  int lines = 1;
  for (char c : text) lines += c == '\n' ? 1 : 0;
  if (r.ok()) {
    ASSERT_FALSE(r.blocks.empty()) << text;
    EXPECT_EQ(r.blocks.back().kind, MotionKind::kEnd) << text;
    const machining::MachineTables t = test_tables();
    for (const MotionBlock& b : r.blocks) {
      EXPECT_GE(b.line, 1);
      EXPECT_LE(b.line, lines);
      EXPECT_GE(b.col, 1);
      for (double v : {b.target.x, b.target.y, b.target.z, b.feed_mm_s, b.z_travel_mm}) {
        EXPECT_TRUE(std::isfinite(v)) << text;
      }
      EXPECT_LE(std::fabs(b.target.x), 100.0 + 1e-6) << text;
      EXPECT_LE(std::fabs(b.target.y), 100.0 + 1e-6) << text;
      EXPECT_GE(b.target.z, -60.0 - 1e-6) << text;
      EXPECT_LE(b.target.z, 20.0 + 1e-6) << text;
      if (b.kind == MotionKind::kDrill) {
        EXPECT_GT(b.z_travel_mm, 0.0);
      }
    }
  } else {
    EXPECT_TRUE(r.blocks.empty());
    for (const GcodeError& e : r.errors) {
      EXPECT_GE(e.line, 1);
      EXPECT_LE(e.line, lines);
      EXPECT_GE(e.col, 1);
      EXPECT_FALSE(e.message.empty());
    }
  }
}

TEST(GcodeFuzz, RandomBytes) {
  std::mt19937 rng(20240601);
  std::uniform_int_distribution<int> len(0, 600);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 3000; ++i) {
    std::string text(static_cast<std::size_t>(len(rng)), '\0');
    for (char& c : text) c = static_cast<char>(byte(rng));
    const GcodeResult r = interpret(text);
    check_answer(text, r);
    EXPECT_FALSE(r.ok());  // random bytes never end with a clean M30
  }
}

TEST(GcodeFuzz, RandomWordSoup) {
  // Plausible words in implausible orders: reaches the interpreter, not just the lexer.
  const std::vector<std::string> vocab{
      "G00", "G01", "G02", "G03", "G04", "G17", "G18", "G20", "G21", "G90", "G91", "G160",
      "M03", "M05", "M08", "M09", "M02", "M30", "E0",  "E1",  "E2",  "E3",  "N10", "(c)",
      ";",   "%",   "\n",  "\n",  "\n",  "\n",  "X",   "Y",   "Z",   "I",   "J",   "P",
      "R",   "F",   "F60", " ",   "(",   ")",   ".",   "-",   "\r"};
  const std::vector<std::string> numbers{"0",   "1",   "-1", "2.5", "-0.5",   "99.9", "150",
                                         "-70", "1e3", "..", "7",   "0.0001", "1000"};
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick_word(0, vocab.size() - 1);
  std::uniform_int_distribution<std::size_t> pick_number(0, numbers.size() - 1);
  std::uniform_int_distribution<int> count(0, 80);
  int clean = 0;
  for (int i = 0; i < 5000; ++i) {
    std::string text;
    const int n = count(rng);
    for (int k = 0; k < n; ++k) {
      const std::string& w = vocab[pick_word(rng)];
      text += w;
      if (w.size() == 1 && w[0] >= 'A' && w[0] <= 'Z') text += numbers[pick_number(rng)];
      text += ' ';
    }
    if (i % 2 == 0) text += "\nM30\n";
    const GcodeResult r = interpret(text);
    check_answer(text, r);
    clean += r.ok() ? 1 : 0;
  }
  // Some soups are valid programs; the property check above then covered real blocks too.
  EXPECT_GT(clean, 0);
}

TEST(GcodeFuzz, HugeInputFinishes) {
  // 2 MB of valid moves: linear time, no quadratic blow-up.
  std::string text;
  for (int i = 0; i < 100000; ++i) text += i % 2 == 0 ? "G00 X1 Y2\n" : "G00 X-1 Y-2\n";
  text += "M30\n";
  const GcodeResult r = interpret(text);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.blocks.size(), 100001u);
}

}  // namespace
}  // namespace edm::hmi::test
