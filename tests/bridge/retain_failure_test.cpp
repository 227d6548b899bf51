// Retained data that could not be kept is never answered ok (issue 31, item 14): offset.set
// answered ok when the retain write was refused, and no alarm was raised. Now the write is
// checked before the reply: a failure undoes the change, answers retain_failed and raises alarm
// 183 (retain_write_failed) until a write succeeds; a retained parameter is not written while
// the file cannot be. The store is made to fail by replacing its file with a directory (the
// writer refuses to rename over one; this works as root too, unlike a read-only directory).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <filesystem>

#include "bridge_fixture.hpp"
#include "programs/sim_machine.hpp"

namespace edm::bridge::test {
namespace {

constexpr const char* kRetainedParam = "cnc.job.manual.jog_v_max_mm_s";

class RetainFailure : public ::testing::Test {
 protected:
  void SetUp() override { build(); }
  void TearDown() override { shut(); }
  void build() {
    std::string text =
        edm::test::read_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
    edm::test::replace_once(
        text, "variables: [io.electrode_length_mm,",
        std::string("variables: [") + kRetainedParam + ", io.electrode_length_mm,");
    rt::BuildOptions bo;
    bo.state_dir = dir_.path().string();
    rt_ = edm::test::build_sim_machine(
        rt::parse_config_text(text,
                              std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml"),
        bo);
    ASSERT_NE(rt_->retain(), nullptr);
    rt_->machine().command(rt::MachineCommand::kPowerOn);
    server_ = start_server(*rt_);
    ASSERT_EQ(c_.connect(client_options(*server_)), Role::kOperator);
  }
  void shut() {
    c_.close();
    if (server_) server_->stop();
    server_.reset();
    rt_.reset();
  }
  bool alarm_183() {
    std::array<rt::ActiveAlarm, 64> a{};
    const std::size_t n = rt_->machine().active_alarms(a.data(), a.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (a[i].code == rt::AlarmCode::kRetainWriteFailed) return true;
    }
    return false;
  }
  void break_the_store() {
    const std::string path = rt_->retain_path();
    std::filesystem::remove(path);
    ASSERT_EQ(::mkdir(path.c_str(), 0700), 0);
  }
  void mend_the_store() { std::filesystem::remove(rt_->retain_path()); }

  edm::test::TempDir dir_{"edm-retain-fail"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  Client c_;
};

TEST_F(RetainFailure, offset_set_answers_retain_failed_changes_nothing_and_raises_183) {
  Reply r = c_.request("offset.set", {{"frame", "G54"}, {"x", 1.5}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["retained"], true);
  EXPECT_FALSE(alarm_183());

  break_the_store();
  r = c_.request("offset.set", {{"frame", "G55"}, {"z", -3.25}});
  expect_error(r, ErrorCode::kRetainFailed);
  EXPECT_NE(r.message.find("G55 is unchanged"), std::string::npos) << r.message;
  EXPECT_EQ(rt_->work_offsets().get(1).z, 0.0) << "not kept, so not set";
  EXPECT_TRUE(alarm_183()) << "the operator is told by an alarm too";
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady) << "a warning, not a fault";
  // A retained parameter is not written while the file cannot be; another one is.
  ASSERT_NE(rt_->variables().find(kRetainedParam), nullptr);
  expect_error(c_.request("var.write", {{"name", kRetainedParam}, {"value", 2.0}}),
               ErrorCode::kRetainFailed);
  EXPECT_TRUE(c_.request("var.write", {{"name", "cnc.job.manual.accel_mm_s2"}, {"value", 150.0}}));

  mend_the_store();
  r = c_.request("offset.set", {{"frame", "G55"}, {"z", -3.25}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_FALSE(alarm_183()) << "cleared by the next good write";

  // What was answered ok is what the next start has.
  shut();
  build();
  EXPECT_EQ(rt_->work_offsets().get(0).x, 1.5);
  EXPECT_EQ(rt_->work_offsets().get(1).z, -3.25);
}

// The electrode length (issue 33): set by the operator, recorded with a work frame's new Z, kept
// across a restart; refused and unchanged when the file cannot be written; bad input refused.
TEST_F(RetainFailure, electrode_set_is_retained_with_the_frames_or_refused_and_unchanged) {
  Reply r = c_.request("electrode.get");
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["length_mm"], 300.0) << "drill-sim's machine.electrode";
  EXPECT_EQ(r.body["known"], true);
  r = c_.request("offset.set", {{"frame", "G54"}, {"z", -2.0}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["z_electrode_mm"], 300.0) << "a new Z records the length it was set with";
  r = c_.request("electrode.set", {{"length_mm", 250.5}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["length_mm"], 250.5);
  EXPECT_EQ(r.body["retained"], true);
  r = c_.request("offset.get");
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["frames"]["G54"]["z_electrode_mm"], 300.0) << "the frame keeps its length";
  EXPECT_EQ(r.body["electrode_mm"], 250.5);
  r = c_.request("offset.set", {{"frame", "G54"}, {"x", 4.0}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["z_electrode_mm"], 300.0) << "only a new Z records a new length";

  for (const Json& bad : {Json{{"length_mm", -1.0}}, Json{{"length_mm", 0.0}},
                          Json{{"length_mm", 2e4}}, Json{{"length_mm", "300"}}, Json::object()}) {
    expect_error(c_.request("electrode.set", bad), ErrorCode::kBadRequest);
  }
  EXPECT_EQ(rt_->electrode().length_mm(), 250.5) << "refused requests change nothing";

  break_the_store();
  r = c_.request("electrode.set", {{"length_mm", 200.0}});
  expect_error(r, ErrorCode::kRetainFailed);
  EXPECT_NE(r.message.find("the electrode length is unchanged"), std::string::npos) << r.message;
  EXPECT_EQ(rt_->electrode().length_mm(), 250.5) << "not kept, so not set";
  EXPECT_TRUE(alarm_183());
  mend_the_store();
  r = c_.request("electrode.set", {{"length_mm", 240.25}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_FALSE(alarm_183()) << "cleared by the next good write";

  shut();
  build();
  EXPECT_EQ(rt_->electrode().length_mm(), 240.25) << "the retained length wins over the config's";
  EXPECT_EQ(rt_->work_offsets().get(0).z, -2.0);
  EXPECT_EQ(rt_->work_offsets().get(0).z_electrode_mm, 300.0);
}

TEST_F(RetainFailure, a_background_write_failure_raises_183_once_and_a_good_one_clears_it) {
  break_the_store();
  ASSERT_EQ(rt_->retain()->sync(), rt::RetainStore::SyncResult::kFailed);
  EXPECT_TRUE(rt_->retain()->failing());
  EXPECT_TRUE(alarm_183());
  ASSERT_EQ(rt_->retain()->sync(), rt::RetainStore::SyncResult::kFailed);
  std::array<rt::ActiveAlarm, 64> a{};
  const std::size_t n = rt_->machine().active_alarms(a.data(), a.size());
  std::uint64_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (a[i].code == rt::AlarmCode::kRetainWriteFailed) count = a[i].count;
  }
  EXPECT_EQ(count, 2u) << "raised once, then counted (latched)";
  mend_the_store();
  EXPECT_EQ(rt_->retain()->sync(), rt::RetainStore::SyncResult::kWritten);
  EXPECT_FALSE(rt_->retain()->failing());
  EXPECT_FALSE(alarm_183());
  EXPECT_EQ(rt_->retain()->sync(), rt::RetainStore::SyncResult::kUnchanged);
}

}  // namespace
}  // namespace edm::bridge::test
