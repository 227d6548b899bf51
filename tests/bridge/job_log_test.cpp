// The job log (issue 33, "a job log"): every job that ended — finished, stopped, or aborted by
// a fault or an E-stop — is kept with its outcome, figures, electrode and alarms, beside the
// retain file as CSV, capped, across restarts. A log file that cannot be read is set aside,
// never a crash and never silently reused.
#include "../../hmi_bridge/server/src/job_log.hpp"  // the log's file format: internal

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "bridge_fixture.hpp"
#include "programs/sim_machine.hpp"
#include "support/runtime_thread.hpp"
#include "support/temp_dir.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;
using machining::MotionBlock;

TEST(JobLogFile, EntriesSurviveAReloadWithTheirTextAndTheCapKeepsTheNewest) {
  edm::test::TempDir dir("edm-job-log");
  const std::string path = dir.file("m.retain.jobs.csv");
  {
    JobLog log(path, 5);
    for (int k = 0; k < 8; ++k) {
      JobLogEntry e;
      e.outcome = k % 2 ? "aborted" : "finished";
      e.time_s = 10.5 + k;
      e.alarms = k == 7 ? "110 block_fault cnc.job: no spark, \"dark\"\nfor 2 s; 130 estop" : "";
      ASSERT_TRUE(log.add(e));
    }
    EXPECT_EQ(log.entries().size(), 5u);
    EXPECT_EQ(log.entries().front().n, 4u) << "the newest five of eight";
  }
  JobLog again(path, 5);
  EXPECT_TRUE(again.load_error().empty()) << again.load_error();
  ASSERT_EQ(again.entries().size(), 5u);
  EXPECT_EQ(again.entries().back().n, 8u);
  EXPECT_EQ(again.entries().back().alarms,
            "110 block_fault cnc.job: no spark, \"dark\"\nfor 2 s; 130 estop");
  EXPECT_EQ(again.entries().back().outcome, "aborted");
  EXPECT_DOUBLE_EQ(again.entries().back().time_s, 17.5);
  JobLogEntry next;
  ASSERT_TRUE(again.add(next));
  EXPECT_EQ(again.entries().back().n, 9u) << "numbering goes on after a restart";
  // The file is CSV with a header row.
  std::ifstream in(path);
  std::string head;
  std::getline(in, head);
  EXPECT_EQ(head.rfind("n,start,end,outcome,slot,dry_run,program,", 0), 0u) << head;
}

TEST(JobLogFile, AFileThatCannotBeReadIsSetAsideAndANewLogBegins) {
  edm::test::TempDir dir("edm-job-log");
  const std::string path = dir.file("m.retain.jobs.csv");
  for (const std::string& text : {std::string("not,a,job,log\n1,2\n"),
                                  JobLog::columns().front() + "\n",  // a wrong header
                                  JobLog({}, 1).csv() + "1,2,3\n",   // a short row
                                  JobLog({}, 1).csv() + "x,,,,,,,,,,,,,,,,\n"}) {
    std::ofstream(path, std::ios::trunc) << text;
    JobLog log(path, 10);
    EXPECT_FALSE(log.load_error().empty()) << text;
    EXPECT_TRUE(log.entries().empty());
    EXPECT_TRUE(std::filesystem::exists(path + ".bad"));
    std::filesystem::remove(path + ".bad");
  }
  // A file too large for a job log is set aside without being read (a sparse 17 MiB file).
  std::ofstream(path, std::ios::trunc).close();
  std::filesystem::resize_file(path, 17u << 20);
  JobLog big(path, 10);
  EXPECT_NE(big.load_error().find("larger than 16 MiB"), std::string::npos) << big.load_error();
  EXPECT_TRUE(std::filesystem::exists(path + ".bad"));
}

// Through the bridge, on drill-sim with a state directory: a finished job, a stopped one and one
// ended by an E-stop, then a restart.
class JobLogOp : public ::testing::Test {
 protected:
  void SetUp() override { build(); }
  void TearDown() override { shut(); }
  void build() {
    rt::BuildOptions bo;
    bo.state_dir = dir_.path().string();
    rt_ = edm::test::build_sim_machine(
        rt::parse_config_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml"), bo);
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
  // Polls jobs.get (the log is written on the server's 100 ms tick) until it holds n jobs.
  Json wait_jobs(std::size_t n) {
    Json body;
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < deadline) {
      const Reply r = c_.request("jobs.get");
      EXPECT_TRUE(r) << r.message;
      body = r.body;
      if (body["jobs"].size() >= n) return body;
      std::this_thread::sleep_for(20ms);  // polling an observable, as a client does
    }
    ADD_FAILURE() << "the log never held " << n << " jobs: " << body;
    return body;
  }
  // Uploads and starts a dwell; returns once the job task has begun it (a stop sent before
  // that cancels the start: no job ran, none is logged).
  void run(double dwell_s) {
    const std::vector<MotionBlock> prog{dwell_block(dwell_s, 1), end_block(2)};
    ASSERT_TRUE(c_.upload_program(prog));
    const std::uint64_t before = rt_->job().progress().jobs_started;
    ASSERT_TRUE(c_.request("cycle.start"));
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (rt_->job().progress().jobs_started == before) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the job never began";
      std::this_thread::sleep_for(1ms);
    }
  }

  edm::test::TempDir dir_{"edm-job-log"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  edm::test::RuntimeThread runner_;
  Client c_;
};

TEST_F(JobLogOp, EachEndedJobIsLoggedWithItsOutcomeAndAlarmsAndKeptAcrossARestart) {
  run(0.05);
  Json log = wait_jobs(1);
  EXPECT_EQ(log["jobs"][0]["outcome"], "finished");
  EXPECT_EQ(log["jobs"][0]["cause"], 0);
  EXPECT_EQ(log["retained"], true);

  run(60.0);
  ASSERT_TRUE(c_.request("cycle.stop"));
  log = wait_jobs(2);
  EXPECT_EQ(log["jobs"][1]["outcome"], "aborted");

  run(60.0);
  ASSERT_TRUE(c_.request("estop"));
  log = wait_jobs(3);
  const Json& e = log["jobs"][2];
  EXPECT_EQ(e["outcome"], "aborted");
  EXPECT_EQ(e["cause"], 130);
  EXPECT_NE(e["alarms"].get<std::string>().find("130 estop"), std::string::npos) << e;
  EXPECT_GT(e["electrode_start_mm"].get<double>(), 0.0);
  EXPECT_EQ(e["n"], 3);

  const Reply csv = c_.request("jobs.get", {{"csv", true}, {"limit", 2}});
  ASSERT_TRUE(csv) << csv.message;
  EXPECT_EQ(csv.body["jobs"].size(), 2u) << "the newest two";
  const std::string text = csv.body["csv"].get<std::string>();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4)
      << "the header and the three jobs: " << text;
  for (const Json& bad :
       {Json{{"limit", 0}}, Json{{"limit", 1001}}, Json{{"limit", "5"}}, Json{{"csv", 1}}}) {
    expect_error(c_.request("jobs.get", bad), ErrorCode::kBadRequest);
  }

  shut();
  build();
  log = wait_jobs(3);
  ASSERT_EQ(log["jobs"].size(), 3u) << "the log is retained";
  EXPECT_EQ(log["jobs"][2]["cause"], 130);
}

}  // namespace
}  // namespace edm::bridge::test
