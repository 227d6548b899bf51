// condition.set (issue 33: "operators may edit the conditions where the config allows, with
// validation"; docs/protocol.md "Conditions") on drill-sim, whose config lets operators change
// E's on and off times, Tdr and servo reference: an edit is taken and shown by machine.info,
// a field the config does not list, a value out of the config's range, an unknown E and a wrong
// state are refused with a precise message and change nothing, and an edit outlives a restart;
// a retained edit the config no longer allows is dropped, an unreadable file set aside.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "bridge_fixture.hpp"
#include "programs/sim_machine.hpp"
#include "support/runtime_thread.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;

class ConditionSet : public ::testing::Test {
 protected:
  void SetUp() override { build(); }
  void TearDown() override { shut(); }
  void build(const std::string& edit_from = "", const std::string& edit_to = "") {
    const std::string file = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";
    std::string text = edm::test::read_file(file);
    if (!edit_from.empty()) edm::test::replace_once(text, edit_from, edit_to);
    rt::BuildOptions bo;
    bo.state_dir = dir_.path().string();
    rt_ = edm::test::build_sim_machine(rt::parse_config_text(text, file), bo);
    server_ = start_server(*rt_);
    runner_.start(*rt_, edm::test::paced_virtual_clock(10.0));
    ASSERT_TRUE(runner_.wait_until_powered_on());
    ASSERT_EQ(c_.connect(client_options(*server_)), Role::kOperator);
  }
  void shut() {
    c_.close();
    runner_.stop();
    if (server_) server_->stop();
    server_.reset();
    rt_.reset();
  }
  /// E1's field as machine.info gives it.
  double e1(const char* field) {
    const Reply info = c_.request("machine.info");  // kept: the loop reads into it
    for (const Json& c : info.body["conditions"]) {
      if (c["E"] == 1) return c[field].get<double>();
    }
    ADD_FAILURE() << "no E1";
    return 0.0;
  }
  std::string refused(const Json& params) {
    const Reply r = c_.request("condition.set", params);
    EXPECT_FALSE(r) << params;
    EXPECT_EQ(r.code, ErrorCode::kBadRequest) << r.message;
    return r.message;
  }

  edm::test::TempDir dir_{"edm-condition-set"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  edm::test::RuntimeThread runner_;
  Client c_;
};

TEST_F(ConditionSet, AnAllowedFieldIsSetCheckedAndRetainedAndNothingElseChanges) {
  const Json info = c_.request("machine.info").body;
  EXPECT_EQ(info["condition_edit"], (Json{"on_time_us", "off_time_us", "tdr_us", "servo_ref_v"}));
  const double on = e1("on_time_us");
  const double current = e1("peak_current_a");

  const Reply r = c_.request("condition.set", {{"E", 1}, {"field", "tdr_us"}, {"value", 9.5}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["retained"], true);
  EXPECT_EQ(e1("tdr_us"), 9.5);
  EXPECT_EQ(rt_->tables().condition(1)->tdr_us, 9.5) << "what the next job's blocks read";

  EXPECT_NE(refused({{"E", 1}, {"field", "peak_current_a"}, {"value", 30.0}})
                .find("'peak_current_a' of a condition may not be changed on this machine"),
            std::string::npos);
  EXPECT_NE(
      refused({{"E", 1}, {"field", "on_time_us"}, {"value", -2.0}}).find("on_time_us must be > 0"),
      std::string::npos);
  EXPECT_NE(refused({{"E", 99}, {"field", "on_time_us"}, {"value", 5.0}})
                .find("this machine has no condition E99"),
            std::string::npos);
  EXPECT_NE(refused({{"E", 1}, {"field", "colour"}, {"value", 5.0}}).find("may not be changed"),
            std::string::npos);
  for (const Json& bad :
       {Json{{"E", "1"}, {"field", "tdr_us"}, {"value", 5.0}}, Json{{"E", 1}, {"field", "tdr_us"}},
        Json{{"E", 1.5}, {"field", "tdr_us"}, {"value", 5.0}},
        Json{{"E", 0}, {"field", "tdr_us"}, {"value", 5.0}}}) {
    refused(bad);
  }
  EXPECT_EQ(e1("on_time_us"), on) << "a refusal changes nothing";
  EXPECT_EQ(e1("peak_current_a"), current);
  EXPECT_EQ(e1("tdr_us"), 9.5);

  shut();
  build();
  EXPECT_EQ(e1("tdr_us"), 9.5) << "retained across a restart";
  EXPECT_EQ(e1("on_time_us"), on);
}

TEST_F(ConditionSet, RefusedWhileAJobRuns) {
  const std::vector<machining::MotionBlock> prog{dwell_block(60.0, 1), end_block(2)};
  ASSERT_TRUE(c_.upload_program(prog));
  ASSERT_TRUE(c_.request("cycle.start"));
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!rt_->job().active()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the job never began";
    std::this_thread::sleep_for(1ms);  // polling an observable state
  }
  const Reply r = c_.request("condition.set", {{"E", 1}, {"field", "tdr_us"}, {"value", 9.0}});
  EXPECT_FALSE(r);
  EXPECT_EQ(r.code, ErrorCode::kInvalidState) << r.message;
  EXPECT_NE(e1("tdr_us"), 9.0);
  ASSERT_TRUE(c_.request("cycle.stop"));
}

TEST_F(ConditionSet, ARetainedEditTheConfigNoLongerAllowsIsDroppedAndABadFileSetAside) {
  ASSERT_TRUE(c_.request("condition.set", {{"E", 1}, {"field", "servo_ref_v"}, {"value", 42.0}}));
  ASSERT_TRUE(c_.request("condition.set", {{"E", 1}, {"field", "tdr_us"}, {"value", 9.0}}));
  shut();
  // The machine builder no longer lets operators change the servo reference.
  build("condition_edit: [on_time_us, off_time_us, tdr_us, servo_ref_v]",
        "condition_edit: [on_time_us, off_time_us, tdr_us]");
  EXPECT_EQ(e1("tdr_us"), 9.0) << "still allowed: kept";
  EXPECT_NE(e1("servo_ref_v"), 42.0) << "no longer allowed: the config's value";
  shut();
  std::string retain;
  for (const auto& f : std::filesystem::directory_iterator(dir_.path())) {
    if (f.path().string().ends_with(".conditions.json")) retain = f.path().string();
  }
  ASSERT_FALSE(retain.empty());
  std::ofstream(retain, std::ios::trunc) << "{\"format\":1,\"edits\":[{\"E\":1,\"field\":";
  build();
  EXPECT_NE(e1("tdr_us"), 9.0) << "an unreadable file: the config's conditions";
  EXPECT_TRUE(std::filesystem::exists(retain + ".bad"));
}

}  // namespace
}  // namespace edm::bridge::test
