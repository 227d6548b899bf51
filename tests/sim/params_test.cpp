#include "edm/sim/params.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace edm::sim {
namespace {

class NameCollector final : public edm::rt::ParamVisitor {
 public:
  std::vector<std::string> names;
  std::vector<std::string> units;

 protected:
  void on_param(std::string_view name, edm::rt::ParamRef /*ref*/,
                edm::rt::ParamInfo info) override {
    names.emplace_back(name);
    units.emplace_back(info.unit);
  }
};

bool has_error(const std::vector<edm::rt::ParamError>& errs, std::string_view field) {
  for (const auto& e : errs) {
    if (e.field == field) return true;
  }
  return false;
}

TEST(SimParams, presets_are_valid_and_distinct) {
  ASSERT_EQ(preset_names().size(), 4U);
  for (const auto& n : preset_names()) {
    const auto p = SimParams::preset(n);
    ASSERT_TRUE(p.has_value()) << n;
    const auto errs = p->validate();
    EXPECT_TRUE(errs.empty()) << n << ": "
                              << (errs.empty() ? "" : errs[0].field + " " + errs[0].message);
  }
  EXPECT_FALSE(SimParams::preset("laser").has_value());
  EXPECT_EQ(SimParams::preset("drill")->tool_kind, "tube");
  EXPECT_EQ(SimParams::preset("sink")->tool_kind, "block");
  EXPECT_EQ(SimParams::preset("wire")->td_law, "quadratic");
  EXPECT_DOUBLE_EQ(SimParams::preset("sink")->peak_current_a, 25.0);
}

TEST(SimParams, visit_names_every_field_once) {
  SimParams p;
  NameCollector c;
  p.visit(c);
  const std::set<std::string> unique(c.names.begin(), c.names.end());
  EXPECT_EQ(unique.size(), c.names.size());
  EXPECT_GE(c.names.size(), 85U);
  EXPECT_TRUE(unique.count("td_gap_ref_um"));
  EXPECT_TRUE(unique.count("wire_thickness_profile"));
  EXPECT_TRUE(unique.count("max_pulses_per_advance"));
}

// Each field against its range first; the rules between fields once every field is in range.
TEST(SimParams, validate_names_the_bad_fields) {
  SimParams p;
  p.peak_current_a = -1.0;
  p.td_law = "cubic";
  p.flush_factor = 1.5;
  p.hole_d_mm = 0.9;  // smaller than the tube
  p.td_len_um = std::nan("");
  auto errs = p.validate();
  EXPECT_TRUE(has_error(errs, "peak_current_a"));
  EXPECT_TRUE(has_error(errs, "flush_factor"));
  EXPECT_TRUE(has_error(errs, "td_len_um"));
  EXPECT_FALSE(has_error(errs, "default_on_time_us"));
  ASSERT_EQ(errs.size(), 3U);
  EXPECT_EQ(errs[0].message, "must be > 0 (got -1)");
  EXPECT_EQ(errs[1].message, "must be a finite number (got nan)");
  EXPECT_EQ(errs[2].message, "must be in [0, 1] (got 1.5)");
  p.peak_current_a = 15.0;
  p.flush_factor = 1.0;
  p.td_len_um = 7.0;
  errs = p.validate();
  EXPECT_TRUE(has_error(errs, "td_law"));
  EXPECT_TRUE(has_error(errs, "hole_d_mm"));
  EXPECT_EQ(errs.size(), 2U);
}

// The plant resolves its parameters once: every one is load time only, but the electrode length
// and the hole a retain store restores at start (docs/simulator.md §5a).
TEST(SimParams, every_field_but_the_electrode_length_and_the_hole_is_load_time_only) {
  struct Check final : edm::rt::ParamVisitor {
    std::vector<std::string> runtime_writable;
    void on_param(std::string_view name, edm::rt::ParamRef, edm::rt::ParamSpec spec) override {
      if (!spec.load_time_only) runtime_writable.emplace_back(name);
    }
  } check;
  SimParams p;
  p.visit(check);
  EXPECT_EQ(
      check.runtime_writable,
      (std::vector<std::string>{"electrode_length_mm", "hole_depth_mm", "hole_x_mm", "hole_y_mm"}));
}

TEST(SimParams, wire_break_shape_must_be_a_whole_number_in_range) {
  for (const double bad : {0.0, 2.5, 65.0, -1.0, std::nan("")}) {
    SimParams p;
    p.wire_break_rab_shape = bad;
    EXPECT_TRUE(has_error(p.validate(), "wire_break_rab_shape")) << bad;
  }
  for (const double good : {1.0, 4.0, 64.0}) {
    SimParams p;
    p.wire_break_rab_shape = good;
    EXPECT_FALSE(has_error(p.validate(), "wire_break_rab_shape")) << good;
  }
}

TEST(SimParams, thickness_profile_parses_and_rejects_precisely) {
  std::string why;
  const auto ok = parse_thickness_profile("0:10, 20:60,40:10", &why);
  ASSERT_TRUE(ok.has_value()) << why;
  ASSERT_EQ(ok->size(), 3U);
  EXPECT_DOUBLE_EQ((*ok)[1].from_mm, 20.0);
  EXPECT_DOUBLE_EQ((*ok)[1].thickness_mm, 60.0);

  EXPECT_FALSE(parse_thickness_profile("0:10,20:", &why));
  EXPECT_NE(why.find("entry 2 ('20:'): thickness is not a number"), std::string::npos) << why;
  EXPECT_FALSE(parse_thickness_profile("0:10,20:60,15:10", &why));
  EXPECT_NE(why.find("entry 3"), std::string::npos) << why;
  EXPECT_NE(why.find("increase"), std::string::npos) << why;
  EXPECT_FALSE(parse_thickness_profile("5:10", &why));
  EXPECT_NE(why.find("start at 0"), std::string::npos) << why;
  EXPECT_FALSE(parse_thickness_profile("0:0", &why));

  auto wire = *SimParams::preset("wire");
  wire.wire_thickness_profile = "0;10";
  const auto errs = wire.validate();
  ASSERT_TRUE(has_error(errs, "wire_thickness_profile"));
}

// A cavity must lie inside the part: from ≤ to, and its void shorter than the thinnest part of
// the profile it overlaps (the slabs above and below keep material).
TEST(SimParams, wire_cavity_is_checked_against_the_profile) {
  auto wire = *SimParams::preset("wire");
  wire.wire_thickness_profile = "0:30,8:12,20:30";
  wire.wire_cavity_from_mm = 5.0;
  wire.wire_cavity_to_mm = 10.0;
  wire.wire_cavity_height_mm = 11.9;
  EXPECT_FALSE(has_error(wire.validate(), "wire_cavity_height_mm"));
  wire.wire_cavity_height_mm = 12.0;  // as tall as the 12 mm section from 8 mm on
  const auto errs = wire.validate();
  ASSERT_TRUE(has_error(errs, "wire_cavity_height_mm"));
  wire.wire_cavity_from_mm = 2.0;  // the cavity ends before the thin section: 12 mm fits
  wire.wire_cavity_to_mm = 8.0;
  EXPECT_FALSE(has_error(wire.validate(), "wire_cavity_height_mm"));
  wire.wire_cavity_from_mm = 9.0;  // from > to
  EXPECT_TRUE(has_error(wire.validate(), "wire_cavity_to_mm"));
  wire.wire_cavity_from_mm = 2.0;
  wire.wire_cavity_flush_mm = 0.0;
  EXPECT_TRUE(has_error(wire.validate(), "wire_cavity_flush_mm"));
  wire.wire_cavity_flush_mm = 1.0;
  wire.wire_cavity_flush_factor = 1.5;
  EXPECT_TRUE(has_error(wire.validate(), "wire_cavity_flush_factor"));
}

}  // namespace
}  // namespace edm::sim
