// Seed 003 fuzzy servo controller: the Mamdani engine, its text encoding, and the integer table.
// The table against direct inference at off-grid inputs: seed_003_lut_vs_inference_test.cpp.

#include "edm/blocks/fuzzy_servo_lut.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "blocks/block_harness.hpp"
#include "edm/blocks/fuzzy_mamdani.hpp"
#include "fuzzy_variables.hpp"

namespace edm::blocks {
namespace {

using test::variable;

TEST(FuzzyServoLUT, default_open_terms_match_the_papers_example) {
  // Paper, Fig. 3: an open count of 23 is 50 % "open", 32 is 100 %.
  const auto open = variable("open", FuzzyServoLUTParams{}.open_terms);
  const int large = open.find("L");
  ASSERT_GE(large, 0);
  EXPECT_DOUBLE_EQ(open.terms[static_cast<std::size_t>(large)].membership(23.0), 0.5);
  EXPECT_DOUBLE_EQ(open.terms[static_cast<std::size_t>(large)].membership(32.0), 1.0);
  // Ruspini partition: the degrees add up to 1 over the whole count range.
  for (int c = 0; c <= 32; ++c) {
    double sum = 0.0;
    for (const auto& t : open.terms) {
      sum += t.membership(c);
    }
    EXPECT_NEAR(sum, 1.0, 1e-15) << "count " << c;
  }
}

TEST(FuzzyServoLUT, the_table_holds_the_papers_integer_codes_at_the_papers_addresses) {
  // Paper, §2.2 (2): y = round(30000 · velocity / 366), velocity in [−5, +5]: the corners are
  // all-open → +5 → round(409.84) = +410, all-short → −410, all-normal → 0.
  BlockHarness<FuzzyServoLUT> h;
  h.start_ok(FuzzyServoLUTParams{});
  const auto& b = h.block();
  EXPECT_EQ(b.code(32, 0), 410);
  EXPECT_EQ(b.code(0, 32), -410);
  EXPECT_EQ(b.code(0, 0), 0);
  EXPECT_DOUBLE_EQ(b.lsb(), 366.0 / (30000.0 * 5.0));
  // Open count = high address, short count = low address, 6 bits each.
  EXPECT_EQ(FuzzyServoLUT::address(32, 0), 32 * 64);
  EXPECT_EQ(FuzzyServoLUT::address(0, 32), 32);
  EXPECT_EQ(FuzzyServoLUT::kWords, 4096);
  // Every code fits the paper's 10-bit word (4096 words × 10 bits = the paper's 40 960 bits).
  for (int o = 0; o < 64; ++o) {
    for (int s = 0; s < 64; ++s) {
      ASSERT_LE(std::abs(int{b.code(o, s)}), 410) << o << "," << s;
      ASSERT_TRUE((o <= 32 && s <= 32) || b.code(o, s) == 0) << "unreadable word " << o << "," << s;
    }
  }
}

TEST(FuzzyServoLUT, corners_all_open_advance_all_short_retract_all_normal_hold) {
  BlockHarness<FuzzyServoLUT> h;
  FuzzyServoLUTParams p;
  p.v_max_mm_s = 2.5;
  ASSERT_TRUE(h.start(p).empty());
  auto& open = h.source<std::int64_t>("open_count");
  auto& shorts = h.source<std::int64_t>("short_count");
  const auto v = [&](std::int64_t o, std::int64_t s) {
    open.set(o);
    shorts.set(s);
    EXPECT_EQ(h.step(), BlockStatus::kOk);
    return h.out("v_mm_s");
  };
  // Read back from the integer code: within half a code of ±v_max (410 · 366 / 30000 = 5.002).
  const double half_code = 2.5 * h.block().lsb() / 2.0;
  EXPECT_NEAR(v(32, 0), +2.5, half_code);
  EXPECT_NEAR(v(0, 32), -2.5, half_code);
  EXPECT_EQ(v(0, 0), 0.0);
}

TEST(FuzzyServoLUT, a_coding_whose_full_scale_overflows_the_int16_table_is_refused) {
  FuzzyServoLUTParams p;
  p.quant_num = 3'000'000;  // 5 · 3e6 / 366 = 40 984 codes
  FuzzyServoLUT blk;
  blk.set_params(p);
  ASSERT_TRUE(blk.validate().empty());
  const auto errs = blk.configure({"test.lut", std::chrono::milliseconds(1)});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "quant_num");
  EXPECT_NE(errs[0].message.find("40984"), std::string::npos) << errs[0].message;
}

TEST(FuzzyServoLUT, monotone_in_open_and_short_over_the_reachable_triangle) {
  BlockHarness<FuzzyServoLUT> h;
  ASSERT_TRUE(h.start(FuzzyServoLUTParams{}).empty());
  const auto& b = h.block();
  for (int o = 0; o <= 32; ++o) {
    for (int s = 0; o + s <= 32; ++s) {
      if (o + 1 + s <= 32) {
        EXPECT_GE(b.table(o + 1, s), b.table(o, s) - 1e-12) << "open " << o << " short " << s;
      }
      if (o + s + 1 <= 32) {
        EXPECT_LE(b.table(o, s + 1), b.table(o, s) + 1e-12) << "open " << o << " short " << s;
      }
    }
  }
  // Strictly useful: more open pulses speed up the advance somewhere, more shorts retract.
  EXPECT_GT(b.table(16, 0), b.table(0, 0));
  EXPECT_LT(b.table(0, 16), b.table(0, 0));
}

TEST(FuzzyServoLUT, centroid_matches_the_analytic_value_for_two_clipped_triangles) {
  // One input, two rules: "open is A → N", "open is B → P" with complementary ramps. The
  // clipped output triangles (half-width 0.5, disjoint) have area w − w²/2 each and centroids at
  // their peaks ±1, so the continuous centroid is (A_P − A_N)/(A_P + A_N).
  std::vector<fuzzy::Variable> in{variable("open", "A=tri(0,0,32) B=tri(0,32,32)")};
  auto out = variable("v", "N=tri(-1.5,-1,-0.5) P=tri(0.5,1,1.5)");
  fuzzy::SyntaxError err;
  auto rules =
      fuzzy::parse_rules("if open is A then v is N; if open is B then v is P", in, out, err);
  ASSERT_TRUE(rules) << err.message;
  const fuzzy::MamdaniEngine eng(in, out, *rules, 30001);
  for (int o = 0; o <= 32; ++o) {
    const double wp = o / 32.0;
    const double wn = 1.0 - wp;
    const double ap = wp - wp * wp / 2.0;
    const double an = wn - wn * wn / 2.0;
    const double x[1] = {double(o)};
    EXPECT_NEAR(eng.infer(x), (ap - an) / (ap + an), 1e-6) << "open " << o;
  }
}

struct BadText {
  const char* field;
  std::string text;
  std::string at;      // the text at the reported position
  std::string expect;  // a fragment of the message
};

TEST(FuzzyServoLUT, malformed_text_is_a_configure_error_naming_field_line_and_column) {
  const std::string ok_rules = FuzzyServoLUTParams{}.rules;
  const std::vector<BadText> cases = {
      {"rules", "if open is L and short is Z than v is PB", "than", "expected 'and' or 'then'"},
      {"rules", "if open is XL then v is PB", "XL", "unknown term 'XL' of 'open'"},
      {"rules", "if opn is L then v is PB", "opn", "unknown input variable 'opn'"},
      {"rules", "if open L then v is PB", "L then", "expected 'is'"},
      {"rules", "if open is L then speed is PB", "speed", "the output variable is 'v'"},
      {"rules", "if open is L then v is PB if open is Z then v is ZE", "if open is Z",
       "expected ';'"},
      {"rules", "if open is L then v is PB;\n  when open is Z then v is ZE", "when",
       "expected 'if'"},
      {"rules", "if normal is Z then v is ZE", "Z then", "unknown term 'Z' of 'normal'"},
      {"rules", "   ", "", "no rules"},
      {"open_terms", "Z=tri(0,0,8) M=tri(0,8) L=tri(8,16,24)", ") L", "expected ','"},
      {"open_terms", "Z=tri(0,0,8) M=tri(8,4,16)", "tri(8,4", "needs a <= b <= c"},
      {"open_terms", "Z=tri(0,0,8) M=gauss(8,2)", "gauss", "expected 'tri' or 'trap'"},
      {"open_terms", "Z=tri(0,0,8) Z=tri(0,8,16)", "Z=tri(0,8", "defined twice"},
      {"velocity_terms", "NB=trap(-1,-1,x,0)", "x,0)", "expected a number"},
  };
  for (const auto& c : cases) {
    FuzzyServoLUTParams p;
    if (std::string(c.field) == "rules") {
      p.rules = c.text;
    } else if (std::string(c.field) == "open_terms") {
      p.open_terms = c.text;
    } else {
      p.velocity_terms = c.text;
    }
    FuzzyServoLUT blk;
    blk.set_params(p);
    ASSERT_TRUE(blk.validate().empty());
    const auto errs = blk.configure({"test.lut", std::chrono::milliseconds(1)});
    ASSERT_EQ(errs.size(), 1u) << c.text << ": " << describe(errs);
    EXPECT_EQ(errs[0].field, c.field);
    EXPECT_NE(errs[0].message.find(c.expect), std::string::npos)
        << c.text << " → " << errs[0].message;
    // The position: line and column of the offending text (1-based, within the string).
    const std::size_t off = c.at.empty() ? 0 : c.text.find(c.at);
    ASSERT_NE(off, std::string::npos);
    int line = 1;
    int col = 1;
    for (std::size_t i = 0; i < off; ++i) {
      if (c.text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    const std::string pos = "at line " + std::to_string(line) + ", column " + std::to_string(col);
    EXPECT_EQ(errs[0].message.rfind(pos, 0), 0u) << c.text << " → " << errs[0].message;
  }
}

TEST(FuzzyServoLUT, a_rule_base_that_leaves_a_reachable_cell_uncovered_is_refused) {
  FuzzyServoLUTParams p;
  p.rules = "if open is L then v is PB; if short is L then v is NB";  // (0, 0) fires nothing
  FuzzyServoLUT blk;
  blk.set_params(p);
  const auto errs = blk.configure({"test.lut", std::chrono::milliseconds(1)});
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].field, "rules");
  EXPECT_NE(errs[0].message.find("open = 0, short = 0"), std::string::npos) << errs[0].message;
}

TEST(FuzzyServoLUT, normal_count_variable_and_custom_rules) {
  // The derived `normal` input: a rule base that holds on normal pulses and advances otherwise.
  FuzzyServoLUTParams p;
  p.normal_terms = "LO=tri(-32,0,32) HI=tri(0,32,64)";
  p.rules = "if normal is HI then v is ZE; if normal is LO then v is PB";
  BlockHarness<FuzzyServoLUT> h;
  const auto errs = h.start(p);
  ASSERT_TRUE(errs.empty()) << describe(errs);
  EXPECT_EQ(h.block().code(0, 0), 0);  // 32 normal
  EXPECT_EQ(h.block().code(32, 0), 410);
  EXPECT_EQ(h.block().code(0, 32), 410);
  EXPECT_GT(h.block().table(10, 10), h.block().table(5, 5));
}

TEST(FuzzyServoLUT, out_of_range_counts_fault_and_hold_the_output) {
  BlockHarness<FuzzyServoLUT> h;
  ASSERT_TRUE(h.start(FuzzyServoLUTParams{}).empty());
  auto& open = h.source<std::int64_t>("open_count");
  auto& shorts = h.source<std::int64_t>("short_count");
  open.set(32);
  ASSERT_EQ(h.step(), BlockStatus::kOk);
  const double v = h.out("v_mm_s");
  open.set(33);
  EXPECT_EQ(h.step(), BlockStatus::kFault);
  open.set(0);
  shorts.set(-1);
  EXPECT_EQ(h.step(), BlockStatus::kFault);
  EXPECT_EQ(h.out("v_mm_s"), v);
}

TEST(FuzzyServoLUT, v_max_is_writable_at_run_time_and_strings_are_not) {
  BlockHarness<FuzzyServoLUT> h;
  ASSERT_TRUE(h.start(FuzzyServoLUTParams{}).empty());
  h.source<std::int64_t>("open_count").set(32);
  ASSERT_TRUE(h.write_param("v_max_mm_s", rt::ParamValue::of_real(1.5)).empty());
  h.step();
  EXPECT_NEAR(h.out("v_mm_s"), 1.5, 1.5 * h.block().lsb() / 2.0);
  EXPECT_FALSE(h.write_param("v_max_mm_s", rt::ParamValue::of_real(-1.0)).empty());
  EXPECT_FALSE(h.block().stage_param(h.param_index("rules"), rt::ParamValue{}).empty());
  EXPECT_FALSE(h.write_param("quant_den", rt::ParamValue::of_int(300)).empty())
      << "the coding filled the table: load time only";
}

}  // namespace
}  // namespace edm::blocks
