// The edmplc process: orderly stop on SIGTERM/SIGINT (stats, trace, retain written), retained
// values restored on restart, byte-identical traces under the virtual clock, bad arguments.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "edm/runtime/retain.hpp"
#include "support/files.hpp"
#include "support/subprocess.hpp"

namespace edm::test {
namespace {

namespace fs = std::filesystem;

class EdmplcProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("edmplc-proc-" + std::to_string(getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    config_ = dir_ / "machine.yaml";
    std::ofstream(config_) << test_data("runtime/integrator_retain.yaml",
                                        {{"retain_file", (dir_ / "retain.dat").string()}});
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> args(std::vector<std::string> extra) {
    std::vector<std::string> a = {EDM_EDMPLC_PATH, "--config", config_.string()};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }

  fs::path dir_;
  fs::path config_;
};

TEST_F(EdmplcProcess, SigtermStopsInOrderAndWritesStatsTraceAndRetain) {
  for (int sig : {SIGTERM, SIGINT}) {
    SCOPED_TRACE(sig);
    fs::remove(dir_ / "retain.dat");
    Child c(args({"--clock", "real", "--stats-out", (dir_ / "stats.json").string(), "--trace-out",
                  (dir_ / "trace.csv").string()}));
    ASSERT_TRUE(c.wait_for_output("running 1 task(s)")) << c.output();
    c.signal(sig);
    EXPECT_EQ(c.wait(), 0) << c.output();
    const std::string stats = read_file(dir_ / "stats.json");
    EXPECT_NE(stats.find("\"name\": \"fast\""), std::string::npos) << stats;
    EXPECT_NE(stats.find("\"latency_us\""), std::string::npos) << stats;
    const std::string trace = read_file(dir_ / "trace.csv");
    EXPECT_EQ(trace.rfind("t_s,task,cycle,p.integ.out,io.ai0\n", 0), 0u) << trace.substr(0, 200);
    // The retain file was flushed at shutdown and holds the integrator's last value.
    const rt::RetainLoadResult r = rt::load_retain_file((dir_ / "retain.dat").string());
    EXPECT_TRUE(r.warning.empty()) << r.warning;
    ASSERT_EQ(r.values.count("p.integ.out"), 1u);
    EXPECT_GE(r.values.at("p.integ.out").r, 0.0);
  }
}

TEST_F(EdmplcProcess, RealClockRunForCoversExactlyTheGridSlotsOfTheDuration) {
  // Whatever the machine's load, every 1 ms slot of [T0, T0 + 200 ms) is a cycle or an omitted
  // cycle, and none beyond.
  Child c(args(
      {"--clock", "real", "--run-for", "200ms", "--stats-out", (dir_ / "stats.json").string()}));
  ASSERT_EQ(c.wait(), 0) << c.output();
  const std::string stats = read_file(dir_ / "stats.json");
  auto number_after = [&](const std::string& key) {
    const auto at = stats.find("\"" + key + "\": ");
    return std::stoull(stats.substr(at + key.size() + 4));
  };
  EXPECT_EQ(number_after("cycles") + number_after("omitted_cycles"), 200u) << stats;
}

TEST_F(EdmplcProcess, RetainedValueIsRestoredOnRestart) {
  // 250 virtual cycles of 1 ms integrate 1.0 → 0.25; the second run continues from there.
  for (double expected : {0.25, 0.5}) {
    Child c(args({"--clock", "virtual", "--run-for", "250ms"}));
    ASSERT_EQ(c.wait(), 0) << c.output();
    const rt::RetainLoadResult r = rt::load_retain_file((dir_ / "retain.dat").string());
    ASSERT_TRUE(r.warning.empty()) << r.warning;
    EXPECT_NEAR(r.values.at("p.integ.out").r, expected, 1e-12);
  }
  // A corrupt retain file is never overwritten with defaults: it is kept aside byte for byte,
  // and the machine comes up in FAULT with alarm 180 (exit 1) so the loss is acknowledged.
  const std::string corrupt = "edmplc-retain 1\ngarbage\n";
  std::ofstream(dir_ / "retain.dat") << corrupt;
  Child c(args({"--clock", "virtual", "--run-for", "250ms"}));
  EXPECT_EQ(c.wait(), 1) << c.output();
  EXPECT_NE(c.output().find("retain_corrupt"), std::string::npos) << c.output();
  EXPECT_NE(c.output().find("retain.dat.corrupt"), std::string::npos) << c.output();
  EXPECT_EQ(read_file(dir_ / "retain.dat.corrupt"), corrupt);
  const rt::RetainLoadResult r = rt::load_retain_file((dir_ / "retain.dat").string());
  EXPECT_NEAR(r.values.at("p.integ.out").r, 0.25, 1e-12);
}

// DESIGN §11: --check and --list-vars never write the retain file — not with good values, not
// with a corrupt file (nothing is set aside either), and a later start restores the values.
TEST_F(EdmplcProcess, CheckAndListVarsNeverWriteTheRetainFile) {
  const fs::path path = dir_ / "retain.dat";
  const std::string corrupt = "edmplc-retain 1\np.integ.out LREAL 1\nend 00000000\n";
  std::ofstream(path, std::ios::binary) << corrupt;
  for (const char* flag : {"--check", "--list-vars"}) {
    Child c(args({flag}));
    EXPECT_EQ(c.wait(), 0) << flag << ": " << c.output();
    EXPECT_EQ(read_file(path), corrupt) << flag;
  }
  rt::write_retain_file_atomic(path.string(), {{"p.integ.out", rt::RetainValue::make_real(42.5)}});
  const std::string good = read_file(path);
  for (const char* flag : {"--check", "--list-vars", "--check"}) {
    Child c(args({flag}));
    EXPECT_EQ(c.wait(), 0) << flag << ": " << c.output();
    EXPECT_EQ(read_file(path), good) << flag << " rewrote the retain file";
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) {
    ++entries;
  }
  EXPECT_EQ(entries, 2U) << "only the config and the retain file: no temp, no .corrupt";
  Child run(args({"--clock", "virtual", "--run-for", "250ms"}));
  ASSERT_EQ(run.wait(), 0) << run.output();
  const rt::RetainLoadResult r = rt::load_retain_file(path.string());
  ASSERT_EQ(r.status, rt::RetainLoadStatus::kLoaded) << r.warning;
  EXPECT_NEAR(r.values.at("p.integ.out").r, 42.75, 1e-9) << "restored 42.5, then 250 ms of 1.0";
}

// A retain.file that is a FIFO, a directory, a device or a link is refused at load time, with
// the file:line:col of `retain.file` (and --check does not hang on the FIFO).
TEST_F(EdmplcProcess, RetainFileThatIsNotARegularFileIsRefusedWithItsLocation) {
  const fs::path fifo = dir_ / "retain.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path target = dir_ / "target.dat";
  rt::write_retain_file_atomic(target.string(), {{"p.integ.out", rt::RetainValue::make_real(1)}});
  const std::string target_bytes = read_file(target);
  const fs::path link = dir_ / "retain.link";
  fs::create_symlink(target, link);
  for (const fs::path& bad : {fifo, dir_, fs::path("/dev/null"), link}) {
    SCOPED_TRACE(bad);
    const fs::path cfg = dir_ / "bad.yaml";
    std::ofstream(cfg) << "version: 1\nmachine: {name: m, io: {driver: loopback}}\n"
                          "tasks:\n  - {name: t, interval: 1ms, programs: [p]}\n"
                          "programs:\n  - name: p\n    blocks:\n"
                          "      - {name: integ, type: Integrator}\n"
                          "retain:\n  file: "
                       << bad.string() << "\n  variables: [p.integ.out]\n";
    for (const char* mode : {"--check", "--run-for"}) {
      std::vector<std::string> a = {EDM_EDMPLC_PATH, "--config", cfg.string(), mode};
      if (std::string(mode) == "--run-for") {
        a.insert(a.end(), {"10ms", "--clock", "virtual"});
      }
      Child c(a);
      EXPECT_EQ(c.wait(), 2) << c.output();
      EXPECT_NE(c.output().find("bad.yaml:10:9: retain.file:"), std::string::npos) << c.output();
    }
  }
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(read_file(target), target_bytes);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST_F(EdmplcProcess, RetainedValueOfTheWrongTypeOrNonFiniteIsNotRestored) {
  const std::string path = (dir_ / "retain.dat").string();
  for (const rt::RetainValue& stale :
       {rt::RetainValue::make_int(5), rt::RetainValue::make_real(std::nan(""))}) {
    rt::write_retain_file_atomic(path, {{"p.integ.out", stale}});
    Child c(args({"--clock", "virtual", "--run-for", "250ms"}));
    ASSERT_EQ(c.wait(), 0) << c.output();
    EXPECT_NE(c.output().find("not restored"), std::string::npos) << c.output();
    const rt::RetainLoadResult r = rt::load_retain_file(path);
    EXPECT_NEAR(r.values.at("p.integ.out").r, 0.25, 1e-12) << "started from the default 0";
  }
}

TEST_F(EdmplcProcess, VirtualClockTracesAreByteIdentical) {
  std::string first;
  for (int run = 0; run < 2; ++run) {
    fs::remove(dir_ / "retain.dat");
    const fs::path out = dir_ / ("trace" + std::to_string(run) + ".csv");
    Child c(args({"--clock", "virtual", "--run-for", "500ms", "--trace-out", out.string()}));
    ASSERT_EQ(c.wait(), 0) << c.output();
    const std::string t = read_file(out);
    EXPECT_EQ(std::count(t.begin(), t.end(), '\n'), 501);
    if (run == 0) {
      first = t;
    } else {
      EXPECT_EQ(t, first);
    }
  }
}

// Issue 17 item 10: a FIFO as the config must not hang --check (no writer ever opens it), nor a
// device or a directory be read: each is a located error and exit 2.
TEST_F(EdmplcProcess, ConfigThatIsNotARegularFileIsRefusedAtOnce) {
  const fs::path fifo = dir_ / "config.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const fs::path& p : {fifo, fs::path("/dev/zero"), dir_}) {
    for (const char* mode : {"--check", "--list-vars"}) {
      Child c({EDM_EDMPLC_PATH, "--config", p.string(), mode});
      EXPECT_EQ(c.wait(), 2) << c.output();
      EXPECT_NE(c.output().find(p.string() + ":1:1: not a regular file"), std::string::npos)
          << c.output();
    }
  }
}

TEST_F(EdmplcProcess, BadArgumentsExitTwoWithAMessage) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--clock", "wall"}, "--clock takes real or virtual"},
      {{"--run-for", "10"}, "needs a unit"},
      {{"--seed", "-1"}, "--seed takes an unsigned"},
      {{"--bridge-port", "70000"}, "--bridge-port takes 0..65535"},
      {{"--frobnicate"}, "unknown argument '--frobnicate'"},
      {{"--seed", "5", "--check"}, "--seed: the 'loopback' driver has no random seed"},
  };
  for (const auto& [extra, message] : cases) {
    Child c(args(extra));
    EXPECT_EQ(c.wait(), 2) << c.output();
    EXPECT_NE(c.output().find(message), std::string::npos) << c.output();
  }
  Child missing({EDM_EDMPLC_PATH, "--config", (dir_ / "nope.yaml").string()});
  EXPECT_EQ(missing.wait(), 2);
  EXPECT_NE(missing.output().find("nope.yaml"), std::string::npos) << missing.output();
}

}  // namespace
}  // namespace edm::test
