// Seed 003 on the simulator: the shipped benchmark config (config/bench/controllers/
// drill-fuzzy-lut.yaml) run by edmplc on the virtual clock, traced every cycle. Two properties:
//  - the simulator's last-32 bitmasks are the real pulse sequence: in every cycle with
//    0 < T ≤ 32 pulses, the newest T bits of io.hist_open / hist_short / hist_arc hold exactly
//    the cycle's io.n_open / n_short / n_transient_arc + n_stable_arc (two outputs of the plant
//    that the counter combines, checked against each other);
//  - the counter reads those registers: on every latch after 32 pulses its counts are the
//    popcounts of the traced bitmasks (arcs as shorts), they sum to 32, and latches are at least
//    m = 32 pulses apart.

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "edm/apps/subprocess.hpp"

namespace {

namespace fs = std::filesystem;

const char* const kVars[] = {
    "io.n_open",           "io.n_normal",           "io.n_short",           "io.n_transient_arc",
    "io.n_stable_arc",     "io.hist_open",          "io.hist_short",        "io.hist_arc",
    "feed.dsc.open_count", "feed.dsc.normal_count", "feed.dsc.short_count", "feed.dsc.data_ready"};

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The shipped config with its trace list replaced by kVars; runs it and returns the CSV rows.
std::vector<std::map<std::string, std::int64_t>> run_traced(int seed, const fs::path& dir) {
  std::string cfg =
      read(fs::path(EDM_SOURCE_DIR) / "config/bench/controllers/drill-fuzzy-lut.yaml");
  const std::size_t at = cfg.find("\ntrace:");
  EXPECT_NE(at, std::string::npos);
  cfg.resize(at + 1);
  cfg += "trace:\n  variables: [";
  for (const char* v : kVars) {
    cfg += std::string(v) + (v == kVars[std::size(kVars) - 1] ? "]\n" : ", ");
  }
  const fs::path yaml = dir / "lut.yaml";
  const fs::path csv = dir / ("trace-" + std::to_string(seed) + ".csv");
  std::ofstream(yaml) << cfg;
  const auto r = edm::apps::run({EDM_EDMPLC_PATH, "--config", yaml.string(), "--clock", "virtual",
                                 "--run-for", "3s", "--seed", std::to_string(seed), "--bridge-port",
                                 "0", "--log-level", "warn", "--trace-out", csv.string()},
                                {}, std::chrono::seconds(120));
  EXPECT_EQ(r.exit_code, 0) << r.error << r.out;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  for (std::stringstream hs(line); std::getline(hs, line, ',');) {
    head.push_back(line);
  }
  std::vector<std::map<std::string, std::int64_t>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::int64_t> row;
    std::stringstream ls(line);
    std::string cell;
    for (std::size_t i = 0; std::getline(ls, cell, ','); ++i) {
      if (i >= 3 && i < head.size()) {  // t_s, task, cycle first
        row[head[i]] = cell == "true" ? 1 : cell == "false" ? 0 : std::stoll(cell);
      }
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

int pc(std::int64_t x) { return std::popcount(static_cast<std::uint64_t>(x)); }

TEST(Seed003SimBitmasks, the_counter_reads_the_simulators_real_pulse_registers) {
  const fs::path dir = fs::temp_directory_path() / ("edm-seed003-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (int seed = 1; seed <= 3; ++seed) {
    const auto rows = run_traced(seed, dir);
    ASSERT_GT(rows.size(), 2900u) << "seed " << seed;
    std::int64_t seen = 0;
    std::int64_t since_latch = 0;
    int checked_cycles = 0;
    int latches = 0;
    std::set<std::int64_t> open_values;
    for (const auto& r : rows) {
      const std::int64_t t = r.at("io.n_open") + r.at("io.n_normal") + r.at("io.n_short") +
                             r.at("io.n_transient_arc") + r.at("io.n_stable_arc");
      seen += t;
      since_latch += t;
      const std::int64_t ho = r.at("io.hist_open");
      const std::int64_t hs = r.at("io.hist_short");
      const std::int64_t ha = r.at("io.hist_arc");
      if (t > 0 && t <= 32) {
        const std::int64_t m = t == 32 ? 0xFFFF'FFFFLL : (std::int64_t{1} << t) - 1;
        ASSERT_EQ(pc(ho & m), r.at("io.n_open")) << "seed " << seed;
        ASSERT_EQ(pc(hs & m), r.at("io.n_short")) << "seed " << seed;
        ASSERT_EQ(pc(ha & m), r.at("io.n_transient_arc") + r.at("io.n_stable_arc"));
        ++checked_cycles;
      }
      if (r.at("feed.dsc.data_ready") != 0) {
        ASSERT_GE(since_latch, 32) << "latches at least m pulses apart";
        since_latch = 0;
        if (seen >= 32) {
          ++latches;
          ASSERT_EQ(r.at("feed.dsc.open_count"), pc(ho)) << "seed " << seed;
          ASSERT_EQ(r.at("feed.dsc.short_count"), pc(hs) + pc(ha)) << "seed " << seed;
          ASSERT_EQ(r.at("feed.dsc.open_count") + r.at("feed.dsc.normal_count") +
                        r.at("feed.dsc.short_count"),
                    32);
          open_values.insert(r.at("feed.dsc.open_count"));
        }
      }
    }
    EXPECT_GT(checked_cycles, 2500) << "seed " << seed;
    EXPECT_GT(latches, 500) << "seed " << seed;
    EXPECT_GT(open_values.size(), 10u) << "the counts follow the gap, seed " << seed;
  }
  fs::remove_all(dir);
}

}  // namespace
