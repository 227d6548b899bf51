// The machine.info reply codec (edm/bridge/machine_info.hpp): a round trip keeps every number,
// and each malformed body is refused with a message naming the bad field.
#include "edm/bridge/machine_info.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace edm::hmi::test {
namespace {

using bridge::Json;
using machining::AxisLimits;
using machining::Condition;
using machining::MachineTables;
using machining::Polarity;

MachineTables drill_tables() {
  MachineTables t;
  t.axes = {{'X', -100.0, 100.0, 30.0, 2000.0},
            {'Y', -90.5, 80.25, 25.0, 1500.0},
            {'Z', -60.0, 20.0, 12.5, 999.75}};
  // e, name, polarity, open V, peak A, on µs, off µs, Tdr µs, servo ref V, wear ratio, area ratio.
  t.conditions = {
      {1, "drill-rough", Polarity::kNegative, 100.0, 15.0, 20.0, 10.0, 8.0, 40.0, 0.6195, 1.3297},
      {7, "wall-finish", Polarity::kPositive, 80.0, 3.5, 2.25, 17.0, 1.5, 33.0, 0.05, 1.0}};
  return t;
}

void expect_same(const MachineTables& a, const MachineTables& b) {
  ASSERT_EQ(a.axes.size(), b.axes.size());
  for (std::size_t i = 0; i < a.axes.size(); ++i) {
    EXPECT_EQ(a.axes[i].name, b.axes[i].name) << i;
    EXPECT_EQ(a.axes[i].min_mm, b.axes[i].min_mm) << i;
    EXPECT_EQ(a.axes[i].max_mm, b.axes[i].max_mm) << i;
    EXPECT_EQ(a.axes[i].v_max_mm_s, b.axes[i].v_max_mm_s) << i;
    EXPECT_EQ(a.axes[i].a_max_mm_s2, b.axes[i].a_max_mm_s2) << i;
  }
  ASSERT_EQ(a.conditions.size(), b.conditions.size());
  for (std::size_t i = 0; i < a.conditions.size(); ++i) {
    const Condition& x = a.conditions[i];
    const Condition& y = b.conditions[i];
    EXPECT_EQ(x.e, y.e) << i;
    EXPECT_EQ(x.name, y.name) << i;
    EXPECT_EQ(x.polarity, y.polarity) << i;
    EXPECT_EQ(x.open_voltage_v, y.open_voltage_v) << i;
    EXPECT_EQ(x.peak_current_a, y.peak_current_a) << i;
    EXPECT_EQ(x.on_time_us, y.on_time_us) << i;
    EXPECT_EQ(x.off_time_us, y.off_time_us) << i;
    EXPECT_EQ(x.tdr_us, y.tdr_us) << i;
    EXPECT_EQ(x.servo_ref_v, y.servo_ref_v) << i;
    EXPECT_EQ(x.wear_ratio, y.wear_ratio) << i;
    EXPECT_EQ(x.area_ratio, y.area_ratio) << i;
  }
}

TEST(MachineInfoCodec, AReplyWithoutAreaRatioMeansThePapersSingleArea) {
  Json body = bridge::to_json(drill_tables(), "drill-sim");
  for (Json& c : body["conditions"]) c.erase("area_ratio");
  MachineTables out;
  std::string name, error;
  ASSERT_TRUE(bridge::from_json(body, out, name, error)) << error;
  for (const Condition& c : out.conditions) EXPECT_EQ(c.area_ratio, 1.0) << c.e;
}

TEST(MachineInfoCodec, RoundTripKeepsEveryField) {
  const MachineTables tables = drill_tables();
  const Json j = bridge::to_json(tables, "drill-sim");
  EXPECT_EQ(j["name"], "drill-sim");
  EXPECT_EQ(j["axes"][1]["name"], "Y");
  EXPECT_EQ(j["conditions"][1]["polarity"], "positive");
  EXPECT_EQ(j["conditions"][0]["E"], 1);
  // Through the text of a line too, as the bridge sends it.
  for (const Json& body : {j, Json::parse(j.dump())}) {
    MachineTables back;
    std::string name, error;
    ASSERT_TRUE(bridge::from_json(body, back, name, error)) << error;
    EXPECT_EQ(name, "drill-sim");
    expect_same(back, tables);
    ASSERT_NE(back.condition(7), nullptr);
    EXPECT_EQ(back.condition(7)->name, "wall-finish");
    ASSERT_NE(back.axis('Z'), nullptr);
    EXPECT_EQ(back.axis('Z')->min_mm, -60.0);
  }
}

TEST(MachineInfoCodec, EmptyTablesRoundTrip) {
  const Json j = bridge::to_json(MachineTables{}, "bare");
  MachineTables back = drill_tables();
  std::string name, error;
  ASSERT_TRUE(bridge::from_json(j, back, name, error)) << error;
  EXPECT_EQ(name, "bare");
  EXPECT_TRUE(back.axes.empty());
  EXPECT_TRUE(back.conditions.empty());
}

struct Malformed {
  std::string what;                 // for the failure message
  std::function<void(Json&)> edit;  // applied to a good body
  std::string names;                // the error must contain this
};

TEST(MachineInfoCodec, EachMalformedBodyIsRefusedNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Malformed> cases = {
      {"not an object", [](Json& j) { j = Json::array(); }, "machine.info"},
      {"no name", [](Json& j) { j.erase("name"); }, "machine.name"},
      {"name a number", [](Json& j) { j["name"] = 3; }, "machine.name"},
      {"no axes", [](Json& j) { j.erase("axes"); }, "'axes'"},
      {"axes an object", [](Json& j) { j["axes"] = Json::object(); }, "'axes'"},
      {"no conditions", [](Json& j) { j.erase("conditions"); }, "'conditions'"},
      {"axis not an object", [](Json& j) { j["axes"][1] = 5; }, "axes[1]: an object"},
      {"axis without name", [](Json& j) { j["axes"][0].erase("name"); }, "axes[0].name"},
      {"axis W", [](Json& j) { j["axes"][2]["name"] = "W"; }, "axes[2].name"},
      {"axis lower-case", [](Json& j) { j["axes"][0]["name"] = "x"; }, "axes[0].name"},
      {"axis min missing", [](Json& j) { j["axes"][1].erase("min_mm"); }, "axes[1].min_mm"},
      {"axis max a string", [](Json& j) { j["axes"][0]["max_mm"] = "100"; }, "axes[0].max_mm"},
      {"axis v_max NaN", [nan](Json& j) { j["axes"][2]["v_max_mm_s"] = nan; },
       "axes[2].v_max_mm_s"},
      {"axis a_max inf", [inf](Json& j) { j["axes"][0]["a_max_mm_s2"] = inf; },
       "axes[0].a_max_mm_s2"},
      {"axis min > max",
       [](Json& j) {
         j["axes"][1]["min_mm"] = 10.0;
         j["axes"][1]["max_mm"] = -10.0;
       },
       "axes[1]: min_mm > max_mm"},
      {"axis twice", [](Json& j) { j["axes"][2]["name"] = "X"; }, "axes[2]: axis X twice"},
      {"condition not an object", [](Json& j) { j["conditions"][0] = "E1"; },
       "conditions[0]: an object"},
      {"E missing", [](Json& j) { j["conditions"][1].erase("E"); }, "conditions[1].E"},
      {"E zero", [](Json& j) { j["conditions"][0]["E"] = 0; }, "conditions[0].E"},
      {"E negative", [](Json& j) { j["conditions"][0]["E"] = -2; }, "conditions[0].E"},
      {"E fractional", [](Json& j) { j["conditions"][1]["E"] = 1.5; }, "conditions[1].E"},
      {"E a string", [](Json& j) { j["conditions"][1]["E"] = "7"; }, "conditions[1].E"},
      {"E twice", [](Json& j) { j["conditions"][1]["E"] = 1; }, "conditions[1]: E1 twice"},
      {"condition name missing", [](Json& j) { j["conditions"][0].erase("name"); },
       "conditions[0].name"},
      {"polarity unknown", [](Json& j) { j["conditions"][1]["polarity"] = "bipolar"; },
       "conditions[1].polarity"},
      {"polarity missing", [](Json& j) { j["conditions"][0].erase("polarity"); },
       "conditions[0].polarity"},
      // area_ratio is optional (an older runtime's reply has none), but never 0, < 0 or absurd.
      {"area_ratio zero", [](Json& j) { j["conditions"][0]["area_ratio"] = 0.0; },
       "conditions[0].area_ratio"},
      {"area_ratio negative", [](Json& j) { j["conditions"][1]["area_ratio"] = -1.3; },
       "conditions[1].area_ratio"},
      {"area_ratio huge", [](Json& j) { j["conditions"][0]["area_ratio"] = 1e9; },
       "conditions[0].area_ratio"},
      {"area_ratio a string", [](Json& j) { j["conditions"][0]["area_ratio"] = "1.3"; },
       "conditions[0].area_ratio"},
  };
  // Every number of a condition, missing and non-finite.
  std::vector<Malformed> all = cases;
  for (const char* field : {"open_voltage_v", "peak_current_a", "on_time_us", "off_time_us",
                            "tdr_us", "servo_ref_v", "wear_ratio"}) {
    const std::string f = field;
    all.push_back(
        {f + " missing", [f](Json& j) { j["conditions"][1].erase(f); }, "conditions[1]." + f});
    all.push_back(
        {f + " NaN", [f, nan](Json& j) { j["conditions"][0][f] = nan; }, "conditions[0]." + f});
    all.push_back(
        {f + " a string", [f](Json& j) { j["conditions"][0][f] = "1"; }, "conditions[0]." + f});
  }
  const Json good = bridge::to_json(drill_tables(), "drill-sim");
  for (const Malformed& m : all) {
    Json body = good;
    m.edit(body);
    MachineTables out = drill_tables();
    out.conditions.pop_back();  // a marker: a refused decode leaves `out` as it was
    std::string name, error;
    EXPECT_FALSE(bridge::from_json(body, out, name, error)) << m.what;
    EXPECT_NE(error.find(m.names), std::string::npos)
        << m.what << ": '" << error << "' does not name " << m.names;
    EXPECT_EQ(out.conditions.size(), 1u) << m.what << ": output changed on failure";
  }
}

}  // namespace
}  // namespace edm::hmi::test
