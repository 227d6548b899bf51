// edmhmi against a real edmplc (config/machines/drill-sim.yaml on the simulator, virtual clock
// paced to 20x wall time, the bridge on a free port): run to the job report, SIGKILL mid-job
// (issue 5: the job completes and a new `edmhmi status` shows it finished), refusals (bad
// program, busy machine, viewer and wrong tokens) and the small commands.
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "process_fixture.hpp"
#include "support/self_signed.hpp"

namespace edm::hmi::test {
namespace {

constexpr double kHoleDepthMm = 15.0;  // drill-then-finish.nc: G01 Z-15
constexpr double kDepthToleranceMm = 0.02;

const std::string kDrillThenFinish = kParts + "drill-then-finish.nc";

TEST_F(EdmhmiProcessTest, RunDrillThenFinishReportsTheFullDepth) {
  start_plc();
  const Outcome r = edmhmi({"run", kDrillThenFinish});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  // The progress (not a terminal: one line per block) showed the drilling.
  EXPECT_NE(r.err.find("depth "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" / 15.000 mm"), std::string::npos) << r.err;
  // The last progress line is the finished job: a full bar.
  const auto last_line = r.err.rfind('\n', r.err.size() - 2);
  const std::string last = r.err.substr(last_line == std::string::npos ? 0 : last_line + 1);
  EXPECT_NE(last.find("] 100% block 15/15 (line 18 end)"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("job report: " + kDrillThenFinish + " on drill-sim\n"), std::string::npos)
      << r.out;
  EXPECT_EQ(row_value(r.out, "outcome"), "finished") << r.out;
  const auto reached = number_after(r.out, "depth reached");
  const auto measured = number_after(r.out, "hole depth (measured)");
  ASSERT_TRUE(reached && measured) << r.out;
  EXPECT_NEAR(*reached, kHoleDepthMm, kDepthToleranceMm) << r.out;
  EXPECT_NEAR(*measured, kHoleDepthMm, kDepthToleranceMm) << r.out;
  // The error column is the reached depth minus the program's.
  const auto error = number_after(r.out, "error");
  ASSERT_TRUE(error) << r.out;
  EXPECT_NEAR(*error, *reached - kHoleDepthMm, 1e-4) << r.out;
  // The orbit finished the wall too.
  const auto wall = number_after(r.out, "wall radius (measured)");
  ASSERT_TRUE(wall) << r.out;
  EXPECT_GT(*wall, 0.55) << r.out;
  EXPECT_EQ(row_value(r.out, "alarms"), "none") << r.out;

  // `status` afterwards: the machine is ready, the job finished, with the same figures.
  const Outcome s = edmhmi({"status"});
  ASSERT_EQ(s.code, 0) << s.out << s.err;
  EXPECT_NE(s.out.find("machine drill-sim  state READY"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("job: finished, program #1"), std::string::npos) << s.out;
  const auto status_depth = number_after(s.out, "cnc.job.job_depth_mm");
  ASSERT_TRUE(status_depth) << s.out;
  EXPECT_NEAR(*status_depth, *reached, 1e-3) << s.out;

  // A finished job does not block the next program (no drilling: no depth row).
  const std::string part = dir_.file("move.nc");
  std::ofstream(part) << "G90 G00 Z5\nG00 X-10 Y10\nG01 X-12 F120\nM30\n";
  const Outcome next = edmhmi({"run", "--quiet", part});
  ASSERT_EQ(next.code, 0) << next.out << next.err;
  EXPECT_EQ(next.err, "");
  EXPECT_EQ(row_value(next.out, "outcome"), "finished") << next.out;
  EXPECT_EQ(row_value(next.out, "depth reached"), "") << next.out;
  const Outcome s2 = edmhmi({"status"});
  EXPECT_NE(s2.out.find("job: finished, program #2"), std::string::npos) << s2.out;
  const auto x = number_after(s2.out, "io.x_mm");
  ASSERT_TRUE(x) << s2.out;
  // (The job ends its last move without waiting for the axes to settle: tens of µm remain.)
  EXPECT_NEAR(*x, -12.0, 0.05) << s2.out;
}

TEST_F(EdmhmiProcessTest, SigkillMidJobTheJobCompletesAndStatusShowsItFinished) {
  start_plc();
  Proc& run = spawn({"run", kDrillThenFinish});
  // Drilling has begun when the progress shows the depth bar.
  ASSERT_TRUE(poll_until([&] { return run.err().find(" / 15.000 mm") != std::string::npos; }, 30s))
      << run.err() << run.out();
  ASSERT_FALSE(run.poll()) << "edmhmi ended before it was killed:\n" << run.out() << run.err();
  run.signal(SIGKILL);
  ASSERT_EQ(run.wait(10s), 128 + SIGKILL);

  // Killed mid-job: nothing stopped the machine.
  const Outcome during = edmhmi({"status"});
  ASSERT_EQ(during.code, 0) << during.out << during.err;
  EXPECT_NE(during.out.find("job: running, program #1"), std::string::npos) << during.out;
  EXPECT_NE(during.out.find("state RUNNING"), std::string::npos) << during.out;

  const Outcome after = status_until("job: finished");
  ASSERT_NE(after.out.find("job: finished, program #1"), std::string::npos)
      << "the job did not finish after edmhmi was killed:\n"
      << after.out << after.err;
  EXPECT_NE(after.out.find("state READY"), std::string::npos) << after.out;
  EXPECT_EQ(after.out.find("(alarm "), std::string::npos) << after.out;
  // The report of `status` (the machine's figures) and its variables show the full depth.
  const auto reached = number_after(after.out, "  depth reached");
  const auto measured = number_after(after.out, "  hole depth (measured)");
  const auto depth = number_after(after.out, "cnc.job.job_depth_mm");
  const auto hole = number_after(after.out, "io.depth_mm");
  ASSERT_TRUE(reached && measured && depth && hole) << after.out;
  EXPECT_NEAR(*reached, kHoleDepthMm, kDepthToleranceMm) << after.out;
  EXPECT_NEAR(*measured, kHoleDepthMm, kDepthToleranceMm) << after.out;
  EXPECT_NEAR(*depth, *reached, 1e-3) << after.out;
  EXPECT_NEAR(*hole, *measured, 1e-3) << after.out;
  // Every block ran: "blocks  N of N".
  std::istringstream in(row_value(after.out, "blocks"));
  std::size_t done = 0, total = 0;
  std::string of;
  in >> done >> of >> total;
  EXPECT_EQ(of, "of");
  EXPECT_GT(total, 0u);
  EXPECT_EQ(done, total) << after.out;
}

TEST_F(EdmhmiProcessTest, InterruptStopsTheJobAndExits130) {
  start_plc();
  Proc& run = spawn({"run", kDrillThenFinish});
  ASSERT_TRUE(poll_until([&] { return run.err().find(" / 15.000 mm") != std::string::npos; }, 30s))
      << run.err() << run.out();
  run.signal(SIGINT);  // Ctrl-C: the operator's stop, not an abandonment
  const auto code = run.wait(30s);
  ASSERT_TRUE(code) << run.err();
  EXPECT_EQ(*code, 130) << run.out() << run.err();
  EXPECT_NE(run.err().find("edmhmi: interrupted: cycle.stop sent"), std::string::npos) << run.err();
  EXPECT_EQ(row_value(run.out(), "outcome"), "aborted") << run.out();
  const auto reached = number_after(run.out(), "depth reached");
  ASSERT_TRUE(reached) << run.out();
  EXPECT_LT(*reached, kHoleDepthMm - 1.0) << run.out();
  const Outcome s = edmhmi({"status"});
  EXPECT_NE(s.out.find("job: aborted, program #1"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("state READY"), std::string::npos) << s.out;
}

TEST_F(EdmhmiProcessTest, ProgramBeyondTheSoftLimitIsRefusedBeforeAnythingIsSent) {
  start_plc();
  const std::string part = dir_.file("too-far.nc");
  std::ofstream(part) << "G17 G21 G90\nG00 Z5\nG00 X150 Y0\nM30\n";
  const Outcome r = edmhmi({"run", part});
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(part + ":3:5: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("soft limit"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("job report"), std::string::npos) << r.out;
  // Nothing reached the machine.
  const Outcome s = edmhmi({"status"});
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("job: no program loaded"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("state READY"), std::string::npos) << s.out;
}

TEST_F(EdmhmiProcessTest, MissingAndMalformedPartProgramsExitTwo) {
  start_plc();
  const Outcome missing = edmhmi({"run", dir_.file("nope.nc")});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find(dir_.file("nope.nc") + ":1:1: cannot open"), std::string::npos)
      << missing.err;
  const std::string part = dir_.file("bad.nc");
  std::ofstream(part) << "G00 Z5\nE9\nM30\n";
  const Outcome bad = edmhmi({"run", part});
  EXPECT_EQ(bad.code, 2) << bad.out << bad.err;
  EXPECT_NE(bad.err.find(part + ":2:1: unknown condition 'E9'"), std::string::npos) << bad.err;
}

TEST_F(EdmhmiProcessTest, BusyMachineRefusesASecondRun) {
  start_plc();
  const Outcome first = edmhmi({"run", "--detach", kDrillThenFinish});
  ASSERT_EQ(first.code, 0) << first.out << first.err;
  EXPECT_NE(first.out.find("started on drill-sim"), std::string::npos) << first.out;
  const Outcome running = status_until("job: running");
  ASSERT_NE(running.out.find("job: running"), std::string::npos) << running.out;

  const Outcome second = edmhmi({"run", kParts + "blind-hole.nc"});
  EXPECT_EQ(second.code, 1) << second.out << second.err;
  EXPECT_NE(second.err.find("edmhmi: the machine is RUNNING with a job"), std::string::npos)
      << second.err;
  EXPECT_NE(second.err.find("stop it first"), std::string::npos) << second.err;
  EXPECT_EQ(second.out.find("job report"), std::string::npos) << second.out;

  // The first job was not disturbed; stop it.
  const Outcome still = edmhmi({"status"});
  EXPECT_NE(still.out.find("job: running, program #1"), std::string::npos) << still.out;
  const Outcome stop = edmhmi({"stop"});
  EXPECT_EQ(stop.code, 0) << stop.out << stop.err;
  const Outcome stopped = status_until("job: aborted");
  EXPECT_NE(stopped.out.find("job: aborted, program #1"), std::string::npos) << stopped.out;
}

/// drill-sim.yaml with an operator and a viewer token (files chmod 600).
class EdmhmiTokenTest : public EdmhmiProcessTest {
 protected:
  void SetUp() override {
    write_token(op_, "op-3c1d77a0b1c2d3e4");
    write_token(viewer_, "viewer-90abf1e2d3c4b5");
    write_token(wrong_, "not-the-token");
    std::string cfg = read_file(kDrillSim);
    const std::string anchor = "\n  port: 7730\n";
    const auto at = cfg.find(anchor);
    ASSERT_NE(at, std::string::npos) << "drill-sim.yaml has no bridge port line";
    cfg.insert(at + anchor.size(),
               "  token_file: " + op_ + "\n  viewer_token_file: " + viewer_ + "\n");
    std::ofstream(config_) << cfg;
    start_plc(config_, "op-3c1d77a0b1c2d3e4");
  }
  static void write_token(const std::string& path, const std::string& token) {
    std::ofstream(path) << token << "\n";
    ::chmod(path.c_str(), 0600);
  }
  std::string op_ = dir_.file("op.token");
  std::string viewer_ = dir_.file("viewer.token");
  std::string wrong_ = dir_.file("wrong.token");
  std::string config_ = dir_.file("drill-sim-tokens.yaml");
};

TEST_F(EdmhmiTokenTest, ViewerMayLookButNotRun) {
  const Outcome status = edmhmi({"--token-file", viewer_, "status"});
  EXPECT_EQ(status.code, 0) << status.out << status.err;
  EXPECT_NE(status.out.find("state READY"), std::string::npos) << status.out;
  const Outcome run = edmhmi({"--token-file", viewer_, "run", kDrillThenFinish});
  EXPECT_EQ(run.code, 1) << run.out << run.err;
  EXPECT_NE(run.err.find("forbidden"), std::string::npos) << run.err;
  const Outcome estop = edmhmi({"--token-file", viewer_, "estop"});
  EXPECT_EQ(estop.code, 1) << estop.out << estop.err;
  EXPECT_NE(estop.err.find("forbidden"), std::string::npos) << estop.err;
  // The viewer's refused run left nothing behind.
  const Outcome after = edmhmi({"status"}, {{"EDM_TOKEN_FILE", op_}});
  EXPECT_EQ(after.code, 0) << after.err;
  EXPECT_NE(after.out.find("job: no program loaded"), std::string::npos) << after.out;
}

TEST_F(EdmhmiTokenTest, WrongOrMissingTokenIsUnauthorized) {
  const Outcome wrong = edmhmi({"--token-file", wrong_, "status"});
  EXPECT_EQ(wrong.code, 1) << wrong.out << wrong.err;
  EXPECT_NE(wrong.err.find("unauthorized"), std::string::npos) << wrong.err;
  EXPECT_NE(wrong.err.find("token from --token-file " + wrong_), std::string::npos) << wrong.err;
  const Outcome env = edmhmi({"run", kDrillThenFinish}, {{"EDM_TOKEN", "guess"}});
  EXPECT_EQ(env.code, 1) << env.out << env.err;
  EXPECT_NE(env.err.find("unauthorized"), std::string::npos) << env.err;
  EXPECT_NE(env.err.find("token from $EDM_TOKEN"), std::string::npos) << env.err;
  const Outcome none = edmhmi({"status"});
  EXPECT_EQ(none.code, 1) << none.out << none.err;
  EXPECT_NE(none.err.find("unauthorized"), std::string::npos) << none.err;
  // The operator's token from the environment works.
  const Outcome op = edmhmi({"status"}, {{"EDM_TOKEN", "op-3c1d77a0b1c2d3e4"}});
  EXPECT_EQ(op.code, 0) << op.err;
  // An empty token file is refused before connecting (bad input).
  const std::string empty = dir_.file("empty.token");
  std::ofstream(empty).close();
  const Outcome bad = edmhmi({"--token-file", empty, "status"});
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("empty first line"), std::string::npos) << bad.err;
}

/// drill-sim.yaml serving TLS with a self-signed certificate made for the test, and a token.
class EdmhmiTlsTest : public EdmhmiTokenTest {
 protected:
  void SetUp() override {
    fingerprint_ = edm::test::make_self_signed(key_, cert_, "edm-test");
    ASSERT_FALSE(fingerprint_.empty()) << "openssl could not make a certificate";
    write_token(op_, "op-3c1d77a0b1c2d3e4");
    std::string cfg = read_file(kDrillSim);
    const std::string anchor = "\n  port: 7730\n";
    const auto at = cfg.find(anchor);
    ASSERT_NE(at, std::string::npos) << "drill-sim.yaml has no bridge port line";
    cfg.insert(at + anchor.size(),
               "  token_file: " + op_ + "\n  tls: {cert: " + cert_ + ", key: " + key_ + "}\n");
    std::ofstream(config_) << cfg;
    edm::bridge::ClientTls tls;
    tls.enabled = true;
    tls.ca_file = cert_;
    start_plc(config_, "op-3c1d77a0b1c2d3e4", tls);
  }
  std::string cert_ = dir_.file("bridge.crt");
  std::string key_ = dir_.file("bridge.key");
  std::string fingerprint_;
};

TEST_F(EdmhmiTlsTest, EdmhmiVerifiesTheServerByCaOrFingerprintAndPlainTcpIsRefused) {
  const Outcome by_ca = edmhmi({"--token-file", op_, "--tls-ca", cert_, "status"});
  EXPECT_EQ(by_ca.code, 0) << by_ca.out << by_ca.err;
  EXPECT_NE(by_ca.out.find("state READY"), std::string::npos) << by_ca.out;
  const Outcome by_pin =
      edmhmi({"status"}, {{"EDM_TOKEN_FILE", op_}, {"EDM_TLS_FINGERPRINT", fingerprint_}});
  EXPECT_EQ(by_pin.code, 0) << by_pin.out << by_pin.err;
  std::string wrong = fingerprint_;
  wrong[0] = wrong[0] == 'A' ? 'B' : 'A';
  const Outcome bad_pin = edmhmi({"--token-file", op_, "--tls-fingerprint", wrong, "status"});
  EXPECT_EQ(bad_pin.code, 1) << bad_pin.out << bad_pin.err;
  EXPECT_NE(bad_pin.err.find("not the pinned one"), std::string::npos) << bad_pin.err;
  const Outcome plain = edmhmi({"--token-file", op_, "status"});
  EXPECT_EQ(plain.code, 1) << plain.out << plain.err;
  EXPECT_NE(plain.err.find("this port speaks TLS"), std::string::npos) << plain.err;
  const Outcome both = edmhmi({"--tls-ca", cert_, "--tls-fingerprint", fingerprint_, "status"});
  EXPECT_EQ(both.code, 2) << both.err;
}

TEST_F(EdmhmiProcessTest, RunRefusesAPartProgramThatIsNotARegularFileBeforeConnecting) {
  const std::string fifo = dir_.file("part.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& part : {dir_.file(""), fifo, std::string("/dev/zero")}) {
    const Outcome r = edmhmi({"run", part}, {}, /*flags=*/false);
    EXPECT_EQ(r.code, 2) << part << ": " << r.err;
    EXPECT_NE(r.err.find(part + ":1:1: "), std::string::npos) << r.err;
  }
}

TEST_F(EdmhmiProcessTest, HoldAndResumeWhenIdleAreInvalidState) {
  start_plc();
  for (const std::string c : {"hold", "resume"}) {
    const Outcome r = edmhmi({c});
    EXPECT_EQ(r.code, 1) << c << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("edmhmi: cycle." + c + ": invalid_state: "), std::string::npos) << r.err;
  }
}

TEST_F(EdmhmiProcessTest, EstopRefusesRunsUntilReset) {
  start_plc();
  const Outcome estop = edmhmi({"estop"});
  EXPECT_EQ(estop.code, 0) << estop.out << estop.err;
  EXPECT_NE(estop.out.find("estop: machine ESTOP"), std::string::npos) << estop.out;
  const Outcome run = edmhmi({"run", kDrillThenFinish});
  EXPECT_EQ(run.code, 1) << run.out << run.err;
  EXPECT_NE(run.err.find("edmhmi: the machine is in ESTOP"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("edmhmi reset"), std::string::npos) << run.err;
  const Outcome s = edmhmi({"status"});
  EXPECT_NE(s.out.find("job: no program loaded"), std::string::npos) << s.out;
  const Outcome reset = edmhmi({"reset"});
  EXPECT_EQ(reset.code, 0) << reset.out << reset.err;
  EXPECT_NE(reset.out.find("reset: machine READY"), std::string::npos) << reset.out;
}

TEST_F(EdmhmiProcessTest, WatchPrintsTheRequestedNumberOfSamples) {
  start_plc();
  // The port from the environment this time.
  const Outcome r =
      edmhmi({"watch", "--rate", "50", "--count", "3", "io.z_mm"},
             {{"EDM_PORT", std::to_string(port_)}, {"EDM_HOST", "127.0.0.1"}}, /*flags=*/false);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    ++n;
    EXPECT_EQ(line.rfind("io.z_mm=", 0), 0u) << line;
    const auto z = number_after(line, "io.z_mm=");
    ASSERT_TRUE(z) << line;
    EXPECT_TRUE(std::isfinite(*z)) << line;
  }
  EXPECT_EQ(n, 3) << r.out;
}

TEST_F(EdmhmiProcessTest, TraceWritesACsvWithIncreasingTime) {
  start_plc();
  const std::string csv = dir_.file("z.csv");
  const Outcome r = edmhmi({"trace", "io.z_mm", "--out", csv, "--duration", "1"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find(" rows to " + csv), std::string::npos) << r.err;
  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t_s,cycle,io.z_mm");
  int rows = 0;
  double last_t = -1.0, first_t = 0.0;
  long long last_cycle = -1, first_cycle = 0;
  while (std::getline(in, line)) {
    double t = 0.0, z = 0.0;
    long long cycle = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lld,%lf", &t, &cycle, &z), 3) << line;
    ASSERT_GT(t, last_t) << "row " << rows << ": " << line;
    ASSERT_GT(cycle, last_cycle) << "row " << rows << ": " << line;
    if (rows == 0) {
      first_t = t;
      first_cycle = cycle;
    }
    // The motion task's releases lie on its 1 ms grid (virtual clock): t_s keeps every digit.
    ASSERT_NEAR(t - first_t, 0.001 * static_cast<double>(cycle - first_cycle), 1e-9)
        << "row " << rows << ": " << line;
    last_t = t;
    last_cycle = cycle;
    ++rows;
  }
  // 1 s of wall time at 20x is about 20,000 cycles of the 1 kHz task; ask for far fewer.
  EXPECT_GT(rows, 100) << r.err;
  const auto reported = number_after(r.err, "edmhmi: ");
  ASSERT_TRUE(reported) << r.err;
  EXPECT_EQ(static_cast<int>(*reported), rows) << r.err;
}

TEST_F(EdmhmiProcessTest, StatsListsTheMotionTask) {
  start_plc();
  const Outcome r = edmhmi({"stats"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("task ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("\nmotion "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nsupervisor "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1000us"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nbridge:"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace edm::hmi::test
