// edm-bench-controllers: the controller benchmark of issue 7 (`./edm bench controllers`).
//
//   edm-bench-controllers [--quick] [--seeds N] [--first-seed S] [--jobs N] [--only ID[,ID…]]
//                         [--root DIR] [--out DIR]
//
// Every scenario × controller × seed runs on the virtual clock (deterministic, as fast as the
// CPU allows), seeds 1 … N for every controller (common random numbers, PLANT-MODEL §6.6;
// --first-seed S runs S … S + N − 1 instead, for studies off the benchmark's seeds), runs
// spread over --jobs threads. Writes <out>/controllers.md (the tables), <out>/<id>.csv and
// <out>/<id>.png (gnuplot) and prints the tables. B7 runs two configs twice with one seed and
// compares every figure bit for bit. Exit: 0 ok, 1 a run failed or B7 differed, 2 bad usage.

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "controllers/bench.hpp"
#include "edm/apps/cli.hpp"

namespace {

using edm::bench::Outcome;

struct Job {
  std::size_t scenario, variant, seed_index;
};

bool identical(const Outcome& a, const Outcome& b) {
  const auto fa = a.fields();
  const auto fb = b.fields();
  for (std::size_t i = 0; i < fa.size(); ++i) {
    if (std::bit_cast<std::uint64_t>(fa[i].second) != std::bit_cast<std::uint64_t>(fb[i].second)) {
      return false;
    }
  }
  return a.jitter_per_cycle_um == b.jitter_per_cycle_um && a.rab_per_s == b.rab_per_s;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int n_seeds = -1;
  long long first_seed = 1;  // the benchmark's seeds are 1 … N; others for studies off them
  unsigned jobs = std::max(1U, std::thread::hardware_concurrency());
  std::string root = EDM_SOURCE_DIR;
  std::string out_dir;
  std::string only;
  CLI::App app("edm-bench-controllers: the controller benchmark (docs/benchmarks.md)",
               "edm-bench-controllers");
  app.add_flag("--quick", quick, "5 seeds and short scenarios");
  app.add_option("--seeds", n_seeds, "seeds per scenario (default 20, 5 with --quick)")
      ->check(edm::apps::kPositive);
  app.add_option("--first-seed", first_seed, "the first seed (the benchmark's are 1 ... N)")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  app.add_option("--jobs", jobs, "parallel runs")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  app.add_option("--root", root, "the source tree")->capture_default_str();
  app.add_option("--out", out_dir, "output directory (default ROOT/out/bench/controllers)");
  app.add_option_function<std::string>(
      "--only", [&](const std::string& v) { only = "," + v + ","; }, "scenario ids, ID,...");
  if (const auto code = edm::apps::parse(
          app, argc, argv,
          "edm-bench-controllers [--quick] [--seeds N] [--first-seed S] [--jobs N] [--only ID,...] "
          "[--root DIR] [--out DIR]")) {
    return *code;
  }
  if (n_seeds < 0) {
    n_seeds = quick ? 5 : 20;
  }
  if (out_dir.empty()) {
    out_dir = root + "/out/bench/controllers";
  }
  std::filesystem::create_directories(out_dir);

  const auto wall0 = std::chrono::steady_clock::now();
  auto scenarios = edm::bench::make_scenarios(quick);
  if (!only.empty()) {
    std::erase_if(scenarios,
                  [&](const auto& s) { return only.find("," + s.id + ",") == std::string::npos; });
  }
  std::vector<std::uint64_t> seeds;
  for (int i = 0; i < n_seeds; ++i) {
    seeds.push_back(static_cast<std::uint64_t>(first_seed + i));
  }
  std::vector<edm::bench::ScenarioResult> results(scenarios.size());
  std::vector<Job> all;
  for (std::size_t s = 0; s < scenarios.size(); ++s) {
    results[s].scenario = &scenarios[s];
    results[s].outcomes.assign(scenarios[s].variants.size(), std::vector<Outcome>(seeds.size()));
    for (std::size_t v = 0; v < scenarios[s].variants.size(); ++v) {
      for (std::size_t k = 0; k < seeds.size(); ++k) {
        all.push_back({s, v, k});
      }
    }
  }
  std::atomic<std::size_t> next_job{0};
  std::atomic<bool> failed{false};
  std::mutex log_mutex;
  auto worker = [&] {
    for (std::size_t j = next_job++; j < all.size(); j = next_job++) {
      const Job& job = all[j];
      edm::bench::RunSpec spec = scenarios[job.scenario].variants[job.variant].spec;
      spec.seed = seeds[job.seed_index];
      try {
        results[job.scenario].outcomes[job.variant][job.seed_index] = edm::bench::run(root, spec);
      } catch (const std::exception& e) {
        const std::lock_guard lock(log_mutex);
        std::fprintf(stderr, "%s / %s / seed %llu: %s\n", scenarios[job.scenario].id.c_str(),
                     scenarios[job.scenario].variants[job.variant].name.c_str(),
                     static_cast<unsigned long long>(spec.seed), e.what());
        failed = true;
      }
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < jobs; ++t) {
    threads.emplace_back(worker);
  }
  for (auto& t : threads) {
    t.join();
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  std::ostringstream md;
  md << "# Controller benchmark (" << (quick ? "--quick" : "full") << ", seeds " << seeds.front()
     << "…" << seeds.back() << ", " << jobs << " threads, "
     << std::to_string(static_cast<int>(wall_s)) << " s wall)\n\n";
  for (const auto& r : results) {
    md << edm::bench::markdown_table(r) << '\n';
    edm::bench::write_csv(out_dir, r, seeds);
    std::fprintf(stderr, "[controllers] plot: %s\n", edm::bench::write_plot(out_dir, r).c_str());
  }

  // B7: the same seed twice gives the same figures, bit for bit.
  bool b7_ok = true;
  if (only.empty() || only.find(",B7,") != std::string::npos) {
    md << "**B7** determinism: the same seed twice\n\n| run | identical |\n|---|---|\n";
    const auto b7 = edm::bench::make_scenarios(true);
    // B1 P; B5 STR, ILC, ILC warm start; B6a fuzzy + grey.
    const std::pair<const char*, std::size_t> picks[] = {
        {"B1", 0}, {"B5", 1}, {"B5", 2}, {"B5", 3}, {"B6a", 1}};
    for (const auto& [id, vi] : picks) {
      const auto it = std::find_if(b7.begin(), b7.end(), [&](const auto& s) { return s.id == id; });
      edm::bench::RunSpec spec = it->variants.at(vi).spec;
      spec.seed = 7;
      spec.limit_s = std::min(spec.limit_s, 10.0);
      const bool same = identical(edm::bench::run(root, spec), edm::bench::run(root, spec));
      b7_ok = b7_ok && same;
      md << "| " << it->id << " " << it->variants[vi].name << ", seed 7, 10 s | "
         << (same ? "yes" : "NO") << " |\n";
    }
    md << '\n';
  }
  const std::string text = md.str();
  std::cout << text;
  std::ofstream(out_dir + "/controllers.md", std::ios::trunc) << text;
  std::fprintf(stderr, "[controllers] %zu runs in %.1f s wall; tables: %s/controllers.md\n",
               all.size(), wall_s, out_dir.c_str());
  return failed || !b7_ok ? 1 : 0;
}
