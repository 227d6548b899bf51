// edm-greyhorizon — redoes seed 000's choice of the grey predictor's horizon p for each
// Butterworth cut-off (Lee & Liao 2003, Table 2) on Rab recorded from the wire simulator.
// Default seeds 1000 … 1004 (issue 20: a tuning set, disjoint from the benchmark's seeds 1-20);
// the RMS curves of the seeds are pooled (RMS² weighted by the samples scored).
// The predictor's form is the block's default, the paper's eq. 1 (`--rho`: the ρ option).
// Records io.rab every 40 ms (the paper's sampling period) from
// config/bench/controllers/wire-horizon.yaml (B6 conditions, fixed settings) on
// the virtual clock, then for each Wn picks p by RMS error against the 50-step moving average
// shifted 25 steps (apps/greyhorizon/horizon.hpp). Same seed → same table.
// Exit codes: 0 ok, 1 the run failed (wire broken, config error), 2 bad arguments.

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/apps/offline_runtime.hpp"
#include "edm/apps/text_file.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "horizon.hpp"

namespace {

using namespace std::chrono_literals;
namespace gh = edm::greyhorizon;
namespace rt = edm::rt;

using edm::apps::kExitOk;
constexpr int kExitFailed = edm::apps::kExitFailure;
constexpr std::int64_t kSampleMs = 40;  // the paper's sampling period of Rab

// Table 2 of the paper: Wn (fraction of Nyquist) and the chosen horizon p.
constexpr std::pair<double, int> kPaperTable[] = {{0.010, 46}, {0.012, 37}, {0.015, 27},
                                                  {0.020, 17}, {0.030, 6},  {0.050, 1}};

constexpr const char* kUsage =
    "edm-greyhorizon [--seed S] [--seeds N] [--samples N] [--skip-s T] [--config PATH]\n"
    "                       [--io PARAMS] [--csv PATH] [--raw PATH] [--max-p P] [--window n]\n"
    "                       [--warmup W] [--rho]";

// Rab every 40 ms from the wire simulator, after skip_ms of cutting.
std::vector<double> record_rab(const std::string& config_path, std::int64_t seed,
                               const std::string& io_extra, std::size_t samples,
                               std::int64_t skip_ms) {
  std::string text = edm::apps::read_text_file(config_path);
  const std::string from = "seed: 1}";
  const auto at = text.find(from);
  if (at == std::string::npos) {
    throw std::runtime_error(config_path + ": no 'seed: 1}' in the io params to replace");
  }
  text.replace(at, from.size(),
               "seed: " + std::to_string(seed) + (io_extra.empty() ? "" : ", " + io_extra) + "}");

  auto r = edm::apps::build_offline(rt::parse_config_text(text, config_path));
  std::vector<rt::Task*> tasks;
  for (const auto& t : r->tasks()) {
    t->detach_trace();
    tasks.push_back(t.get());
  }
  r->machine().command(rt::MachineCommand::kPowerOn);
  auto pin = [&](const std::string& name) {
    const rt::Variable* v = r->variables().find(name);
    if (v == nullptr || !v->is_pin()) {
      throw std::runtime_error(config_path + ": no pin '" + name + "'");
    }
    return v->pin;
  };
  const rt::PinRef rab = pin("io.rab");
  const rt::PinRef broken = pin("io.wire_broken");

  rt::VirtualClock clock;
  rt::VirtualScheduler sched(tasks, clock);
  std::vector<double> x;
  x.reserve(samples);
  const std::int64_t end_ms = skip_ms + static_cast<std::int64_t>(samples) * kSampleMs;
  for (std::int64_t k = 1; k <= end_ms; ++k) {
    sched.run_until(rt::TimePoint{1ms * k});
    if (k > skip_ms && (k - skip_ms) % kSampleMs == 0) {
      if (rt::read_pin_as_double(broken) != 0.0) {
        throw std::runtime_error("the wire broke at t = " + std::to_string(k) +
                                 " ms: the record would be dead");
      }
      x.push_back(rt::read_pin_as_double(rab));
    }
  }
  return x;
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t seed = 1000;
  std::int64_t seeds = 5;
  bool rho = false;
  std::int64_t samples = 3000;
  std::int64_t skip_s = 30;
  std::int64_t max_p = 60;
  std::int64_t window = 5;
  std::int64_t warmup = 300;
  std::string config = std::string(EDM_SOURCE_DIR) + "/config/bench/controllers/wire-horizon.yaml";
  std::string csv;
  std::string raw;
  std::string io_extra;
  CLI::App app(
      "edm-greyhorizon: the grey-model horizon p for each Wn (seed 000 Table 2) on "
      "the Rab recorded from the wire simulator",
      "edm-greyhorizon");
  app.add_option("--seed", seed, "first simulator seed (tuning set: >= 1000)")
      ->check(CLI::Range(std::int64_t{0}, INT64_MAX))
      ->capture_default_str();
  app.add_option("--seeds", seeds, "records pooled: seeds S … S + N − 1")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000}))
      ->capture_default_str();
  app.add_flag("--rho", rho,
               "predict with the exact discrete rho instead of the paper's eq. 1 (paper_exp: "
               "false)");
  app.add_option("--samples", samples, "Rab samples at 40 ms (default 3000 = 120 s)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{10'000'000}));
  app.add_option("--skip-s", skip_s,
                 "simulated seconds before the record starts (default 30: the kerf debris "
                 "settles)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{100'000}));
  app.add_option("--config", config, "wire machine config")->capture_default_str();
  app.add_option("--io", io_extra,
                 "extra simulator params, e.g. \"wire_thickness_profile: '0:10,40:30'\"");
  app.add_option("--csv", csv, "also write the pooled RMS error for every Wn and p to PATH");
  app.add_option("--raw", raw,
                 "also write the first seed's recorded Rab (one sample a line) to PATH");
  app.add_option("--max-p", max_p, "largest horizon tried")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{10'000}))
      ->capture_default_str();
  app.add_option("--window", window, "GM(1,1) window n (as the block)")
      ->check(CLI::Range(std::int64_t{4}, std::int64_t{1024}))
      ->capture_default_str();
  app.add_option("--warmup", warmup, "samples not scored at the start")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{10'000'000}))
      ->capture_default_str();
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) return *code;

  gh::HorizonOptions opt;
  opt.max_horizon = static_cast<std::size_t>(max_p);
  opt.window = static_cast<std::size_t>(window);
  opt.warmup = static_cast<std::size_t>(warmup);
  opt.paper_exp = !rho;
  try {
    std::vector<std::vector<double>> records;
    for (std::int64_t sd_i = 0; sd_i < seeds; ++sd_i) {
      records.push_back(record_rab(config, seed + sd_i, io_extra, static_cast<std::size_t>(samples),
                                   skip_s * 1000));
    }
    for (std::size_t i = 0; i < records.size(); ++i) {
      const std::vector<double>& x = records[i];
      double mean = 0;
      for (double v : x) mean += v;
      mean /= static_cast<double>(x.size());
      double var = 0;
      for (double v : x) var += (v - mean) * (v - mean);
      const double sd = std::sqrt(var / static_cast<double>(x.size()));
      // How much slow content the record has: the objective's SD against white noise's
      // SD/√L (a white record leaves the L-step average nothing else to follow).
      const auto o = gh::shifted_moving_average(x, opt.ma_length, opt.ma_shift);
      double om = 0, on = 0, ov = 0;
      for (std::size_t k = opt.warmup; k < o.size(); ++k) {
        if (!std::isnan(o[k])) {
          om += o[k];
          on += 1;
        }
      }
      om /= on > 0 ? on : 1;
      for (std::size_t k = opt.warmup; k < o.size(); ++k) {
        if (!std::isnan(o[k])) ov += (o[k] - om) * (o[k] - om);
      }
      std::printf(
          "Rab from %s, seed %lld: %zu samples at %lld ms, mean %.3f, SD %.3f; objective SD "
          "%.5f (white noise of the same SD would give %.5f)\n",
          config.c_str(), static_cast<long long>(seed + static_cast<std::int64_t>(i)), x.size(),
          static_cast<long long>(kSampleMs), mean, sd, std::sqrt(ov / (on > 0 ? on : 1)),
          sd / std::sqrt(static_cast<double>(opt.ma_length)));
    }
    std::printf(
        "GM(1,1) window %zu, %s form, p = 0..%zu, objective: %zu-step moving average shifted "
        "%zu, scored after %zu samples; %zu record(s) pooled\n\n",
        opt.window, opt.paper_exp ? "eq. 1 (paper)" : "rho", opt.max_horizon, opt.ma_length,
        opt.ma_shift, opt.warmup, records.size());
    std::printf(
        "| Wn | p (ours) | p per seed | RMS at p | RMS at p = 0 | RMS at paper's p | p (paper) | "
        "filter DC delay |\n|---|---|---|---|---|---|---|---|\n");
    std::vector<gh::HorizonResult> results;
    for (const auto& [wn, paper_p] : kPaperTable) {
      std::vector<gh::HorizonResult> per_seed;
      std::string ps;
      for (const auto& x : records) {
        per_seed.push_back(gh::choose_horizon(x, wn, opt));
        ps += (ps.empty() ? "" : " ") + std::to_string(per_seed.back().best_p);
      }
      gh::HorizonResult res = gh::pool_horizons(per_seed);
      const auto pp = static_cast<std::size_t>(paper_p);
      const double at_paper = pp < res.rms.size() ? res.rms[pp] : std::nan("");
      std::printf("| %.3f | %zu | %s | %.5f | %.5f | %.5f | %d | %.1f |\n", wn, res.best_p,
                  ps.c_str(), res.best_rms, res.rms[0], at_paper, paper_p,
                  gh::butterworth_dc_delay(wn));
      results.push_back(std::move(res));
    }
    if (!csv.empty()) {
      std::ofstream out(csv);
      if (!out) throw std::runtime_error(csv + ": cannot write");
      out << "p";
      for (const auto& res : results) out << ",rms_wn_" << res.wn;
      out << "\n";
      for (std::size_t p = 0; p <= opt.max_horizon; ++p) {
        out << p;
        for (const auto& res : results) out << "," << res.rms[p];
        out << "\n";
      }
    }
    if (!raw.empty()) {
      std::ofstream out(raw);
      if (!out) throw std::runtime_error(raw + ": cannot write");
      for (double v : records.front()) out << v << "\n";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edm-greyhorizon: %s\n", e.what());
    return kExitFailed;
  }
  return kExitOk;
}
