// The electrode table (issue 33, "Electrodes"): its entries survive a restart with their history,
// the wear ratio is the length lost per depth drilled up to the last measurement, it is bounded,
// and a file that cannot be read is set aside, never a crash and never silently reused.
#include "../../hmi_bridge/server/src/electrode_table.hpp"  // the table's file format: internal

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/temp_dir.hpp"

namespace edm::bridge::test {
namespace {

ElectrodeEntry electrode(const std::string& id, double length_mm) {
  ElectrodeEntry e;
  e.id = id;
  e.kind = "tube";
  e.size_mm = 1.0;
  e.material = "copper";
  e.new_length_mm = length_mm;
  e.length_mm = length_mm;
  e.unmeasured = true;
  return e;
}

TEST(ElectrodeTableFile, AnElectrodesHistoryAndWearRatioSurviveARestart) {
  edm::test::TempDir dir("edm-electrodes");
  const std::string path = dir.file("m.retain.electrodes.json");
  {
    ElectrodeTable t(path);
    EXPECT_EQ(t.current(), nullptr);
    ASSERT_TRUE(t.change(electrode("E1", 300.0), 0.0, "t0"));
    t.measured(299.0);  // its first measurement is its new length
    EXPECT_DOUBLE_EQ(t.current()->new_length_mm, 299.0);
    EXPECT_FALSE(t.current()->measured_wear_ratio()) << "nothing drilled yet";
    t.add_job("E1", 3, 36.0, 270.0);  // three 12 mm holes, the estimate says 29 mm worn
    t.add_job("E1", 1, 12.0, 260.0);
    EXPECT_NEAR(*t.current()->estimated_wear_ratio(), 39.0 / 48.0, 1e-12);
    EXPECT_FALSE(t.current()->measured_wear_ratio()) << "not measured since it drilled";
    t.measured(263.0);  // the setter says 3 mm less worn than estimated
    EXPECT_NEAR(*t.current()->measured_wear_ratio(), 36.0 / 48.0, 1e-12);
    // Another one in the spindle; E1 keeps the length it was taken out with.
    ASSERT_TRUE(t.change(electrode("E2", 250.0), 262.5, "t1"));
    EXPECT_DOUBLE_EQ(t.find("E1")->length_mm, 262.5);
    ASSERT_TRUE(t.save());
  }
  ElectrodeTable again(path);
  EXPECT_TRUE(again.load_error().empty()) << again.load_error();
  ASSERT_EQ(again.entries().size(), 2u);
  ASSERT_NE(again.current(), nullptr);
  EXPECT_EQ(again.current()->id, "E2");
  EXPECT_TRUE(again.current()->unmeasured);
  const ElectrodeEntry* e1 = again.find("E1");
  ASSERT_NE(e1, nullptr);
  EXPECT_EQ(e1->holes, 4);
  EXPECT_DOUBLE_EQ(e1->drilled_mm, 48.0);
  EXPECT_NEAR(*e1->measured_wear_ratio(), 36.0 / 48.0, 1e-12);
  // E1 back in: its history goes on.
  ASSERT_TRUE(again.change(electrode("E1", 0.0), 250.0, "t2"));
  EXPECT_DOUBLE_EQ(again.current()->length_mm, 262.5);
  EXPECT_EQ(again.current()->holes, 4);
}

TEST(ElectrodeTableFile, TheTableIsBoundedAndItsFieldsAreChecked) {
  ElectrodeTable t("");
  for (std::size_t k = 0; k < ElectrodeTable::kCap; ++k) {
    ASSERT_TRUE(t.change(electrode("E" + std::to_string(k), 100.0), 100.0, "t"));
  }
  EXPECT_FALSE(t.change(electrode("one-more", 100.0), 100.0, "t")) << "full";
  EXPECT_TRUE(t.change(electrode("E7", 100.0), 100.0, "t")) << "a known one may come back";
  EXPECT_EQ(t.entries().size(), ElectrodeTable::kCap);
  EXPECT_TRUE(ElectrodeTable::invalid_id("Cu-1.5_a").empty());
  for (const std::string& id : {std::string(), std::string("E 1"), std::string("E/1"),
                                std::string(33, 'x'), std::string("É")}) {
    EXPECT_FALSE(ElectrodeTable::invalid_id(id).empty()) << id;
  }
  EXPECT_FALSE(ElectrodeTable::invalid_kind("hex").empty());
  EXPECT_FALSE(ElectrodeTable::invalid_material("").empty());
  EXPECT_FALSE(ElectrodeTable::invalid_material("a\tb").empty());
}

TEST(ElectrodeTableFile, AFileThatCannotBeReadIsSetAsideAndANewTableBegins) {
  edm::test::TempDir dir("edm-electrodes");
  const std::string path = dir.file("m.retain.electrodes.json");
  const std::string good_entry =
      R"({"id":"E1","kind":"tube","size_mm":1,"material":"cu","new_length_mm":300,)"
      R"("length_mm":290,"holes":1,"drilled_mm":12,"measured_length_mm":0,)"
      R"("drilled_at_measure_mm":0,"changed":"t","unmeasured":false})";
  const auto doc = [](const std::string& entries) {
    return R"({"format":"edmplc electrodes 1","current":"E1","electrodes":[)" + entries + "]}";
  };
  std::string bad_id = good_entry;
  bad_id.replace(bad_id.find("\"E1\""), 4, "\"E 1\"");
  std::string negative = good_entry;
  negative.replace(negative.find("\"length_mm\":290"), 15, "\"length_mm\":-1");
  for (const std::string& text :
       {std::string("not json"), std::string("{}"), std::string(R"({"format":"x"})"),
        doc(R"({"id":"E1"})"), doc(bad_id), doc(negative),
        doc(good_entry + "," + good_entry) /* one id twice */}) {
    std::ofstream(path, std::ios::trunc) << text;
    ElectrodeTable t(path);
    EXPECT_FALSE(t.load_error().empty()) << text;
    EXPECT_TRUE(t.entries().empty());
    EXPECT_EQ(t.current(), nullptr);
    EXPECT_TRUE(std::filesystem::exists(path + ".bad")) << text;
    std::filesystem::remove(path + ".bad");
  }
  std::ofstream(path, std::ios::trunc) << doc(good_entry);
  ElectrodeTable ok(path);
  EXPECT_TRUE(ok.load_error().empty()) << ok.load_error();
  ASSERT_NE(ok.current(), nullptr);
  EXPECT_DOUBLE_EQ(ok.current()->length_mm, 290.0);
  // A file too large for a table is set aside without being read (a sparse 5 MiB file).
  std::ofstream(path, std::ios::trunc).close();
  std::filesystem::resize_file(path, 5u << 20);
  ElectrodeTable big(path);
  EXPECT_NE(big.load_error().find("larger than 4 MiB"), std::string::npos) << big.load_error();
}

}  // namespace
}  // namespace edm::bridge::test
