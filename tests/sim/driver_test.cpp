// The simulator as the I/O driver of edmplc: determinism by seed, parameter overrides and their
// errors, load-time-only parameters.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/files.hpp"
#include "support/subprocess.hpp"
#include "support/temp_dir.hpp"

namespace edm::test {
namespace {

namespace fs = std::filesystem;

const std::string kDrill = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim-program.yaml";

TEST(SimDriver, SameSeedGivesByteIdenticalTracesAndAnotherSeedDoesNot) {
  TempDir dir("edm-sim");
  auto run = [&](const std::string& seed, const std::string& out) {
    Child c({EDM_EDMPLC_PATH, "--config", kDrill, "--clock", "virtual", "--run-for", "30s",
             "--seed", seed, "--trace-out", dir.file(out)});
    EXPECT_EQ(c.wait(), 0) << c.output();
    return read_file(dir.file(out));
  };
  const std::string a = run("7", "a.csv");
  const std::string b = run("7", "b.csv");
  const std::string c = run("8", "c.csv");
  EXPECT_EQ(std::count(a.begin(), a.end(), '\n'), 30001);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(SimDriver, RealClockLatchAdvancesThePlantFromTheFirstLatchOnly) {
  // The plant starts at the first latch: a first cycle that tried to simulate CLOCK_MONOTONIC's
  // whole history would take seconds. (No watchdog here: a loaded CI machine must not fault it.)
  TempDir dir("edm-sim");
  std::string cfg = read_file(kDrill);
  cfg.erase(cfg.find("    watchdog:"),
            cfg.find("\n", cfg.find("    watchdog:")) + 1 - cfg.find("    watchdog:"));
  std::ofstream(dir.file("m.yaml")) << cfg;
  Child c({EDM_EDMPLC_PATH, "--config", dir.file("m.yaml"), "--clock", "real", "--run-for", "300ms",
           "--stats-out", dir.file("s.json")});
  ASSERT_EQ(c.wait(), 0) << c.output();
  const std::string stats = read_file(dir.file("s.json"));
  const auto exec = stats.find("\"exec_us\"");
  const auto max_at = stats.find("\"max\": ", exec);
  EXPECT_LT(std::stod(stats.substr(max_at + 7)), 100000.0) << stats;
}

TEST(SimDriver, TheShippedMachinesPassCheck) {
  for (const char* m : {"drill-sim", "sink-sim", "wire-sim", "wire-process-sim", "sink-str-sim"}) {
    Child c({EDM_EDMPLC_PATH, "--check", "--config",
             std::string(EDM_SOURCE_DIR) + "/config/machines/" + m + ".yaml"});
    EXPECT_EQ(c.wait(), 0) << m << ": " << c.output();
  }
}

struct BadSim {
  const char* params;
  const char* message;
};

TEST(SimDriver, BadParametersAreLocatedErrors) {
  TempDir dir("edm-sim");
  const BadSim cases[] = {
      {"{preset: drll}", "unknown preset 'drll' (presets: drill, sink, wire, wire-xy)"},
      {"{preset: drill, peak_current_a: fast}", "parameter 'peak_current_a' is LREAL"},
      {"{preset: drill, peak_curent_a: 10}", "unknown parameter 'peak_curent_a'"},
      {"{preset: drill, peak_current_a: -5}", "peak_current_a"},
      {"{preset: drill, seed: -1}", "seed must be >= 0"},
      {"{preset: drill, work_x_min_mm: 10, work_x_max_mm: 5}", "work_x_max_mm"},
      {"{preset: drill, work_bore_d_mm: 30, work_bore_x_mm: 40}", "must lie inside the work"},
  };
  for (const BadSim& b : cases) {
    const std::string path = dir.file("bad.yaml");
    std::ofstream(path) << "version: 1\nmachine:\n  name: m\n  io: {driver: sim, params: "
                        << b.params
                        << "}\ntasks:\n  - {name: t, interval: 1ms, priority: 0, programs: [p]}\n"
                           "programs:\n  - {name: p, blocks: []}\n";
    Child c({EDM_EDMPLC_PATH, "--check", "--config", path});
    EXPECT_EQ(c.wait(), 2) << b.params << ": " << c.output();
    EXPECT_NE(c.output().find(path + ":4:"), std::string::npos) << c.output();
    EXPECT_NE(c.output().find(b.message), std::string::npos) << c.output();
  }
}

}  // namespace
}  // namespace edm::test
