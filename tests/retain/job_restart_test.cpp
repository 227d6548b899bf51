// Restart after an unclean stop (issue 19 item 5, DESIGN §11): a real edmplc on
// config/machines/drill-sim.yaml (virtual clock paced to 20x, its state directory a temp dir),
// a part program started by `edmhmi run --detach`, then SIGKILL in the middle of drilling. The
// restart comes up in FAULT with alarm 182 naming the program, block, line and depth, and the
// simulator's electrode is the retained one. A job that finished leaves no alarm, even when the
// process is killed afterwards.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "edm/apps/subprocess.hpp"
#include "edm/runtime/retain.hpp"
#include "support/files.hpp"
#include "support/free_port.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using edm::test::read_file;

const std::string kSource = EDM_SOURCE_DIR;
const std::string kDrillSim = kSource + "/config/machines/drill-sim.yaml";
const std::string kBlindHole = kSource + "/examples/parts/blind-hole.nc";  // N70 G01 Z-20

template <class F>
bool poll_until(F done, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(20ms);  // the polling interval of an observable file
  }
}

class JobRestart : public ::testing::Test {
 protected:
  JobRestart() : dir_("edm-job-restart") { retain_ = dir_.file("state/drill-sim.retain"); }
  void TearDown() override {
    for (auto& p : children_) p.kill();
  }

  edm::apps::Process& spawn(std::vector<std::string> argv, const std::string& name) {
    edm::apps::SpawnOptions o;
    o.out = o.err = edm::apps::Stream::kFile;
    o.out_file = dir_.file(name + ".out");
    o.err_file = dir_.file(name + ".err");
    o.unset_env = {"EDM_HOST", "EDM_PORT", "EDM_TOKEN_FILE", "EDM_TOKEN"};
    o.set_env = {{"EDM_STATE_DIR", dir_.file("state")}};
    children_.emplace_back(argv, o);
    return children_.back();
  }
  std::string log(const std::string& name) const {
    return read_file(dir_.file(name + ".out")) + read_file(dir_.file(name + ".err"));
  }

  // edmplc with its bridge on a free port, up when it says so.
  // Another port is tried when the free one was taken in between.
  edm::apps::Process& start_plc() {
    for (int attempt = 0;; ++attempt) {
      port_ = edm::test::free_port();
      auto& plc = spawn({EDM_EDMPLC_PATH, "--config", kDrillSim, "--clock", "virtual", "--speed",
                         "20", "--bridge-port", std::to_string(port_)},
                        "plc");
      EXPECT_TRUE(plc.started()) << plc.error();
      const bool up = poll_until(
          [&] {
            return plc.poll().has_value() ||
                   log("plc").find("bridge: listening on") != std::string::npos;
          },
          20s);
      if (up && !plc.ended()) return plc;
      if (attempt < 2 && log("plc").find("in use") != std::string::npos) continue;
      ADD_FAILURE() << "edmplc did not come up (" << plc.describe() << "):\n" << log("plc");
      return plc;
    }
  }
  int edmhmi(const std::vector<std::string>& args, const std::string& name) {
    std::vector<std::string> argv{EDM_EDMHMI_PATH, "--host", "127.0.0.1", "--port",
                                  std::to_string(port_)};
    argv.insert(argv.end(), args.begin(), args.end());
    auto& p = spawn(argv, name);
    return p.wait(120s).value_or(-1);
  }
  RetainMap retained() const { return load_retain_file(retain_).values; }
  // Until the retained job record says `running` and a depth beyond `min_depth_mm`.
  bool wait_for_record(bool running, double min_depth_mm, std::chrono::milliseconds timeout) {
    return poll_until(
        [&] {
          const RetainMap m = retained();
          return m.contains("job.running") && m.at("job.running").b == running &&
                 m.contains("job.depth_mm") && m.at("job.depth_mm").r > min_depth_mm;
        },
        timeout);
  }

  // The restart: 2 s of virtual time, the trace of io.electrode_mm, no bridge.
  int restart(const std::string& name) {
    auto& p = spawn({EDM_EDMPLC_PATH, "--config", kDrillSim, "--clock", "virtual", "--run-for",
                     "2s", "--bridge-port", "0", "--trace-out", dir_.file(name + ".csv")},
                    name);
    return p.wait(60s).value_or(-1);
  }
  // io.electrode_mm of the trace's first row.
  std::optional<double> first_electrode(const std::string& name) const {
    const std::string csv = read_file(dir_.file(name + ".csv"));
    const auto eol = csv.find('\n');
    if (eol == std::string::npos) return std::nullopt;
    std::vector<std::string> head;
    for (std::size_t a = 0, b; a <= eol; a = b + 1) {
      b = csv.find_first_of(",\n", a);
      head.push_back(csv.substr(a, b - a));
      if (b == eol) break;
    }
    std::size_t col = 0;
    while (col < head.size() && head[col] != "io.electrode_mm") ++col;
    std::size_t at = eol + 1;
    for (std::size_t k = 0; k < col; ++k) at = csv.find(',', at) + 1;
    return std::stod(csv.substr(at, csv.find_first_of(",\n", at) - at));
  }

  edm::test::TempDir dir_;
  std::string retain_;
  int port_{0};
  std::deque<edm::apps::Process> children_;  // a deque: references stay valid
};

TEST_F(JobRestart, KillMidDrillingRestartsInFaultWithTheJobAndTheElectrode) {
  auto& plc = start_plc();
  ASSERT_EQ(edmhmi({"run", "--detach", kBlindHole}, "run"), 0) << log("run");
  // Drilling: the record says a job runs and the hole is 3 mm deep (retained at most ~1 s old).
  ASSERT_TRUE(wait_for_record(true, 3.0, 90s)) << log("plc");
  plc.kill();
  ASSERT_EQ(plc.term_signal(), SIGKILL);
  const RetainMap at_kill = retained();
  const double electrode = at_kill.at("io.electrode_length_mm").r;
  const double depth = at_kill.at("job.depth_mm").r;
  const std::int64_t block = at_kill.at("job.block").i;
  const std::int64_t line = at_kill.at("job.line").i;
  EXPECT_GT(line, 0);
  EXPECT_NE(at_kill.at("job.program").i, 0) << "the bridge names the program by its CRC-32";
  EXPECT_LT(electrode, 300.0) << "the electrode wore while drilling";

  // Safe at power-on: FAULT (exit 1 after --run-for), alarm 182 with block, line and depth.
  EXPECT_EQ(restart("again"), 1) << log("again");
  const std::string out = log("again");
  char want[160];
  std::snprintf(want, sizeof want, "block %lld of ", static_cast<long long>(block));
  EXPECT_NE(out.find("ALARM 182 (job_interrupted) from job"), std::string::npos) << out;
  EXPECT_NE(out.find(want), std::string::npos) << out;
  EXPECT_NE(out.find("(G-code line " + std::to_string(line) + ")"), std::string::npos) << out;
  std::snprintf(want, sizeof want, "depth %.3f mm", depth);
  EXPECT_NE(out.find(want), std::string::npos) << out;
  // The simulator's electrode is the retained length from the first cycle (in FAULT: no wear).
  const auto restored = first_electrode("again");
  ASSERT_TRUE(restored.has_value());
  EXPECT_NEAR(*restored, electrode, 1e-9);
  // The record stays until the next job begins: a second unclean stop still names the job.
  const RetainMap kept = retained();
  EXPECT_TRUE(kept.at("job.running").b);
  EXPECT_EQ(kept.at("job.block").i, block);
  EXPECT_EQ(restart("third"), 1);
  EXPECT_NE(log("third").find("ALARM 182"), std::string::npos);
}

TEST_F(JobRestart, FinishedJobThenKillRestartsWithoutTheAlarm) {
  auto& plc = start_plc();
  ASSERT_EQ(edmhmi({"run", "--quiet", kBlindHole}, "run"), 0) << log("run");
  // The job's end reaches the disk at once (the running flag is written without min_interval).
  ASSERT_TRUE(wait_for_record(false, 19.0, 20s)) << log("plc");
  const double electrode = retained().at("io.electrode_length_mm").r;
  plc.kill();
  EXPECT_EQ(restart("again"), 0) << log("again");
  EXPECT_EQ(log("again").find("182"), std::string::npos) << log("again");
  const auto restored = first_electrode("again");
  ASSERT_TRUE(restored.has_value());
  // Idle after the job: the length retained is the length left.
  EXPECT_NEAR(*restored, electrode, 1e-9);
}

// Issue 21 item 6: after kill -9 in the middle of drilling, the restart comes up in FAULT (alarm
// 182), the operator resets and runs the part from the drilling block's line: the re-approach
// (rapid up, over, down to the block's start, E1 re-armed) and the drill, counting from the depth
// the interrupted job had reached, finish the hole to its programmed depth. The simulated work
// keeps its half-drilled hole across the restart (retained, like a real workpiece).
TEST_F(JobRestart, KillMidDrillingThenRunFromTheBlockFinishesTheHole) {
  auto& plc = start_plc();
  ASSERT_EQ(edmhmi({"run", "--detach", kBlindHole}, "run"), 0) << log("run");
  ASSERT_TRUE(wait_for_record(true, 6.0, 90s)) << log("plc");
  plc.kill();
  const RetainMap at_kill = retained();
  const double depth_at_kill = at_kill.at("job.depth_mm").r;
  const double hole_at_kill = at_kill.at("io.hole_depth_mm").r;
  // The controller's estimate and the simulated hole were written together: they agree.
  EXPECT_NEAR(depth_at_kill, hole_at_kill, 0.03);
  EXPECT_LT(hole_at_kill, 19.0);

  auto& again = start_plc();
  ASSERT_EQ(edmhmi({"reset"}, "reset"), 0) << log("reset");
  // blind-hole.nc: N70 G01 Z-20.0 (the drilling block) is on source line 10.
  ASSERT_EQ(edmhmi({"run", "--quiet", "--from", "10", kBlindHole}, "resume"), 0)
      << log("resume") << log("plc");
  const std::string out = log("resume");
  EXPECT_NE(out.find("finished"), std::string::npos) << out;
  again.signal(SIGTERM);
  ASSERT_TRUE(again.wait(60s).has_value());
  const double hole = retained().at("io.hole_depth_mm").r;
  std::printf(
      "killed at %.4f mm (estimate %.4f mm); resumed from line 10: hole %.4f mm "
      "(program 20 mm, error %+.1f um)\n",
      hole_at_kill, depth_at_kill, hole, (hole - 20.0) * 1e3);
  EXPECT_NEAR(hole, 20.0, 0.05);
}

TEST_F(JobRestart, WithoutAStateDirectoryNothingIsRetained) {
  edm::apps::SpawnOptions o;
  o.out = edm::apps::Stream::kPipe;
  o.err = edm::apps::Stream::kStdout;
  o.unset_env = {"EDM_STATE_DIR"};
  edm::apps::Process p({EDM_EDMPLC_PATH, "--config", kDrillSim, "--clock", "virtual", "--run-for",
                        "100ms", "--bridge-port", "0"},
                       o);
  ASSERT_EQ(p.wait(60s).value_or(-1), 0) << p.output();
  EXPECT_NE(p.output().find("no state directory is set"), std::string::npos) << p.output();
}

}  // namespace
}  // namespace edm::rt
