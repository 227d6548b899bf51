#pragma once
// Shared by the G-code tests: the test machine (E1 drilling, E2 finishing; X/Y ±100, Z −60..20)
// and helpers that interpret a program and fail the test on unexpected errors.

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_tables.hpp"

namespace edm::hmi::test {

using machining::MotionBlock;
using machining::MotionKind;

inline machining::MachineTables test_tables() {
  machining::MachineTables t;
  t.conditions.push_back({.e = 1,
                          .name = "drill-rough",
                          .polarity = machining::Polarity::kNegative,
                          .tdr_us = 8.0,
                          .wear_ratio = 0.6,
                          .area_ratio = 1.25});
  t.conditions.push_back({.e = 2,
                          .name = "wall-finish",
                          .polarity = machining::Polarity::kPositive,
                          .tdr_us = 6.0,
                          .wear_ratio = 0.05});
  t.axes.push_back({.name = 'X', .min_mm = -100.0, .max_mm = 100.0});
  t.axes.push_back({.name = 'Y', .min_mm = -100.0, .max_mm = 100.0});
  t.axes.push_back({.name = 'Z', .min_mm = -60.0, .max_mm = 20.0});
  return t;
}

inline GcodeResult interpret(std::string_view text, const GcodeOptions& options = {}) {
  return interpret_gcode(text, "t.nc", test_tables(), options);
}

inline std::string joined(const GcodeResult& r) {
  std::string s;
  for (const std::string& m : r.messages()) s += m + "\n";
  return s;
}

/// The blocks of a program that must interpret cleanly ("M30" is appended, and its end block
/// removed from the answer after checking it is there).
inline std::vector<MotionBlock> blocks_of(const std::string& body,
                                          const GcodeOptions& options = {}) {
  const GcodeResult r = interpret(body + "\nM30\n", options);
  EXPECT_TRUE(r.ok()) << joined(r);
  std::vector<MotionBlock> b = r.blocks;
  if (b.empty() || b.back().kind != MotionKind::kEnd) {
    ADD_FAILURE() << "no end block";
    return b;
  }
  b.pop_back();
  return b;
}

/// The blocks of one kind, in order.
inline std::vector<MotionBlock> of_kind(const std::vector<MotionBlock>& blocks, MotionKind k) {
  std::vector<MotionBlock> out;
  for (const MotionBlock& b : blocks)
    if (b.kind == k) out.push_back(b);
  return out;
}

/// The messages of a program that must be refused ("M30" appended).
inline std::vector<std::string> errors_of(const std::string& body) {
  const GcodeResult r = interpret(body + "\nM30\n");
  EXPECT_FALSE(r.ok()) << body;
  EXPECT_TRUE(r.blocks.empty());
  return r.messages();
}

/// The first error; "" when there is none (the test then fails on the comparison).
inline std::string first_error(const std::string& body) {
  const std::vector<std::string> e = errors_of(body);
  return e.empty() ? std::string() : e.front();
}

}  // namespace edm::hmi::test
