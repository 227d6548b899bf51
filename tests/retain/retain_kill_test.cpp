// Acceptance test of the atomic write: a writer killed with SIGKILL at random moments never leaves
// a retain file that fails to load or mixes two iterations.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <system_error>

#include "edm/apps/subprocess.hpp"
#include "edm/runtime/retain.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

using TempDir = edm::test::TempDir;

constexpr int kVariables = 200;  // ~7 KB file: several write() pages of work per iteration
constexpr int kTrials = 60;      // acceptance asks for >= 50 kills
constexpr std::int64_t kTrialStride = 1'000'000;  // iteration numbers of trial t: t*stride + 1, ...
constexpr std::uint64_t kSeed = 0x5EED'0EDB'2024ULL;

// Every value is a function of the iteration, so a file mixing two iterations is detected.
RetainMap iteration_map(std::int64_t it) {
  RetainMap m;
  m.emplace("prog.writer.iteration", RetainValue::make_int(it));
  for (int k = 0; k < kVariables; ++k) {
    char name[48];
    std::snprintf(name, sizeof name, "prog.block%03d.pin", k);
    switch (k % 3) {
      case 0: m.emplace(name, RetainValue::make_int(it * 1000 + k)); break;
      case 1: m.emplace(name, RetainValue::make_real(static_cast<double>(it) * 0.1 + k)); break;
      default: m.emplace(name, RetainValue::make_bool(((it + k) & 1) != 0)); break;
    }
  }
  return m;
}

// Child: write iterations forever, reporting each completed (renamed) one on stdout (a pipe).
[[noreturn]] void child_loop(const std::string& path, std::int64_t first) {
  for (std::int64_t it = first;; ++it) {
    write_retain_file_atomic(path, iteration_map(it));
    const char done = 1;
    if (::write(STDOUT_FILENO, &done, 1) != 1) {
      ::_exit(4);
    }
  }
}

// Reads n completion reports; false if the child died or went silent.
bool wait_for_reports(edm::apps::Process& child, std::size_t n) {
  while (child.output().size() < n) {
    if (!child.read_some(std::chrono::seconds(10))) {
      return false;
    }
  }
  return true;
}

void busy_spin(std::chrono::nanoseconds d) {
  const auto until = Clock::now() + d;
  while (Clock::now() < until) {
  }
}

TEST(RetainKill9, file_always_loads_whole_and_from_one_iteration) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  // Calibrate the kill window to this disk: spin up to two iterations past the report.
  const auto t0 = Clock::now();
  constexpr int kCalibration = 5;
  for (int k = 0; k < kCalibration; ++k) {
    write_retain_file_atomic(path, iteration_map(0));
  }
  const auto iteration_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0) / kCalibration;

  std::mt19937_64 rng(kSeed);
  std::uniform_int_distribution<int> reports_dist(1, 5);
  std::uniform_int_distribution<std::int64_t> spin_dist(0, 2 * iteration_ns.count());
  int kills_leaving_temp = 0;
  for (int trial = 1; trial <= kTrials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial) + ", seed " + std::to_string(kSeed));
    const std::int64_t first = trial * kTrialStride + 1;
    edm::apps::SpawnOptions reports_only;
    reports_only.err = edm::apps::Stream::kInherit;
    edm::apps::Process writer =
        edm::apps::Process::fork_call([&] { child_loop(path, first); }, reports_only);
    ASSERT_TRUE(writer.started()) << writer.error();
    const pid_t pid = writer.pid();
    const int reports = reports_dist(rng);
    const bool alive = wait_for_reports(writer, static_cast<std::size_t>(reports));
    busy_spin(std::chrono::nanoseconds(spin_dist(rng)));
    writer.kill();
    ASSERT_TRUE(alive) << "writer stopped reporting";
    ASSERT_EQ(writer.term_signal(), SIGKILL) << writer.describe();
    // The temp name is `path.tmp.<pid>.<random>`: look for the killed writer's prefix.
    const std::string killed_prefix =
        fs::path(path).filename().string() + ".tmp." + std::to_string(pid) + ".";
    for (const auto& e : fs::directory_iterator(fs::path(path).parent_path())) {
      if (e.path().filename().string().starts_with(killed_prefix)) {
        ++kills_leaving_temp;
      }
    }

    const RetainLoadResult loaded = load_retain_file(path);
    ASSERT_EQ(loaded.warning, "");
    ASSERT_TRUE(loaded.values.contains("prog.writer.iteration"));
    const std::int64_t it = loaded.values.at("prog.writer.iteration").i;
    // At least every reported write is visible, and nothing from an earlier trial.
    EXPECT_GE(it, first + reports - 1);
    EXPECT_LT(it, first + kTrialStride);
    EXPECT_TRUE(loaded.values == iteration_map(it))
        << "file mixes iterations (iteration " << it << ")";
  }
  RecordProperty("kills_leaving_temp", kills_leaving_temp);
  std::printf("[ info ] %d kills, %d mid-write (temp left), iteration ~%lld us\n", kTrials,
              kills_leaving_temp, static_cast<long long>(iteration_ns.count() / 1000));

  // Every leftover temp is a killed writer's, and the store's start-up sweep removes them all.
  EXPECT_EQ(remove_stale_retain_temps(path), static_cast<std::size_t>(kills_leaving_temp));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) {
    ++entries;
  }
  EXPECT_EQ(entries, 1U);
}

}  // namespace
}  // namespace edm::rt
