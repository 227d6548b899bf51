// edm-bench-jitter: release jitter of edmplc against cyclictest, side by side in one run.
//
// For each variant (1 kHz, 10 kHz) it alternates A = edmplc running config/bench/jitter*.yaml and
// B = cyclictest at the same SCHED_FIFO priority and period, one at a time, --rounds times, then
// prints every run and the medians over rounds with the edmplc/cyclictest ratios against the
// targets. docs/benchmarks.md is the manual. Exit: 0 measured (even when a target is missed),
// 1 a tool failed, 2 bad arguments.

#include <fmt/core.h>
#include <fmt/format.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench_util.hpp"
#include "edm/apps/cli.hpp"
#include "jitter_parse.hpp"

namespace fs = std::filesystem;
using edm::bench::child_failure;
using edm::bench::ChildResult;
using edm::bench::read_file;
using edm::bench::run_child;
using edm::bench::RunStats;
using edm::bench::tail_lines;
using edm::bench::TempDir;

namespace {

constexpr int kFifoPriority = 90;  // edmplc maps task priority p to SCHED_FIFO 90 - p
constexpr double kTargetP99Ratio = 1.2;
constexpr double kTargetMaxRatio = 2.0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

struct Variant {
  const char* name;    // as given to --only
  const char* config;  // relative to --root
  int interval_us;     // must match what edmplc reports for the config's fastest task
};
constexpr Variant kVariants[] = {{"1k", "config/bench/jitter.yaml", 1000},
                                 {"10k", "config/bench/jitter-10k.yaml", 100}};

struct Options {
  std::string edmplc;
  std::string root;
  int duration_s{10};
  int rounds{2};
  std::string only;
  std::optional<int> cpu;
};

constexpr const char* kUsage =
    "edm-bench-jitter --edmplc PATH --root DIR [--duration 10s] [--rounds 2] [--only 1k|10k]\n"
    "                        [--cpu N]\n"
    "       edm-bench-jitter --parse cyclictest|edmplc FILE";

struct RunRecord {
  const char* variant;
  int round;
  std::string tool;
  RunStats stats;
  std::string note;
};

void print_run(const RunRecord& r) {
  std::string extra = r.note;
  if (r.tool == "edmplc") {
    extra = fmt::format("overruns {}, omitted {}{}{}", r.stats.overruns, r.stats.omitted_cycles,
                        r.note.empty() ? "" : "; ", r.note);
  }
  fmt::print(
      "  {:<4} round {:<2} {:<10}  cycles {:>8}  p50 {:>8.1f}  p99 {:>8.1f}  max {:>8.1f} us"
      "{}{}\n",
      r.variant, r.round, r.tool, r.stats.cycles, r.stats.p50_us, r.stats.p99_us, r.stats.max_us,
      extra.empty() ? "" : "  ", extra);
  std::fflush(stdout);
}

/// One A (edmplc) run. Returns an error text, empty on success.
std::string run_edmplc(const Options& opt, const Variant& v, const fs::path& tmp, int round,
                       RunStats& stats, std::string& note) {
  const fs::path stats_path = tmp / fmt::format("edmplc-{}-r{}.json", v.name, round);
  const fs::path err_path = tmp / fmt::format("edmplc-{}-r{}.stderr", v.name, round);
  const std::vector<std::string> args{opt.edmplc,
                                      "--config",
                                      (fs::path(opt.root) / v.config).string(),
                                      "--clock",
                                      "real",
                                      "--run-for",
                                      fmt::format("{}s", opt.duration_s),
                                      "--stats-out",
                                      stats_path.string()};
  const ChildResult r =
      run_child(args, err_path, opt.cpu, std::chrono::seconds(opt.duration_s + 60));
  if (auto failure = child_failure("edmplc", r, err_path); !failure.empty()) {
    return failure;
  }
  std::string error;
  const auto parsed = edm::bench::parse_edmplc_stats(read_file(stats_path), error);
  if (!parsed) {
    return fmt::format("edmplc: cannot use {}: {}", stats_path.string(), error);
  }
  if (parsed->interval_us != v.interval_us) {
    return fmt::format("edmplc: {}'s fastest task runs every {} us, the {} variant needs {} us",
                       v.config, parsed->interval_us, v.name, v.interval_us);
  }
  stats = *parsed;
  // DESIGN §6: without the right to use SCHED_FIFO edmplc warns and runs SCHED_OTHER.
  if (read_file(err_path).find("SCHED_OTHER") != std::string::npos) {
    note = "WARNING: edmplc ran SCHED_OTHER, not comparable";
  }
  return {};
}

/// The cyclictest command line of a variant: same FIFO priority and period as edmplc's fast task.
std::vector<std::string> cyclictest_args(const Options& opt, const Variant& v,
                                         const std::string& cyclictest) {
  // 1 us buckets up to 2 periods (at least 1 ms); later samples count as overflows (and max).
  const int hist_max_us = std::max(1000, 2 * v.interval_us);
  std::vector<std::string> args{cyclictest, "-m", "-q", "--policy=fifo"};
  args.insert(args.end(),
              {"-p", std::to_string(kFifoPriority), "-i", std::to_string(v.interval_us)});
  args.insert(args.end(), {"-D", std::to_string(opt.duration_s), "-t", "1"});
  args.insert(args.end(), {"-h", std::to_string(hist_max_us)});
  if (opt.cpu) {
    args.insert(args.end(), {"-a", std::to_string(*opt.cpu)});
  }
  return args;
}

/// One B (cyclictest) run. Returns an error text, empty on success.
std::string run_cyclictest(const Options& opt, const Variant& v, const std::string& cyclictest,
                           const fs::path& tmp, int round, RunStats& stats) {
  const std::vector<std::string> args = cyclictest_args(opt, v, cyclictest);
  const fs::path err_path = tmp / fmt::format("cyclictest-{}-r{}.stderr", v.name, round);
  const ChildResult r =
      run_child(args, err_path, opt.cpu, std::chrono::seconds(opt.duration_s + 60));
  if (auto failure = child_failure("cyclictest", r, err_path); !failure.empty()) {
    return failure;
  }
  std::string error;
  const auto report = edm::bench::parse_cyclictest(r.out, error);
  if (!report) {
    return fmt::format("cyclictest: cannot parse its output: {}\n{}", error, tail_lines(r.out, 8));
  }
  stats = report->stats();
  return {};
}

std::string ratio_text(double num, double den, double target, const char* what) {
  if (den <= 0.0) {
    return fmt::format("{} ratio n/a (cyclictest 0)", what);
  }
  const double ratio = num / den;
  return fmt::format("{} {:.3f} (target <= {:.1f}) {}", what, ratio, target,
                     ratio <= target ? "PASS" : "MISS");
}

int parse_args(int argc, char** argv, Options& opt) {
  CLI::App app(
      "edm-bench-jitter: release jitter of edmplc against cyclictest "
      "(docs/benchmarks.md)",
      "edm-bench-jitter");
  app.footer(
      "edm-bench-jitter --parse cyclictest|edmplc FILE: print the stats parsed from a recorded "
      "cyclictest -h output or edmplc --stats-out file");
  app.add_option("--edmplc", opt.edmplc, "the edmplc binary")->required();
  app.add_option("--root", opt.root, "the source tree")->required();
  app.add_option_function<std::string>(
      "--duration",
      [&](const std::string& v) {
        const auto s = edm::bench::parse_seconds(v);
        if (!s) edm::apps::reject("--duration takes whole seconds as 10s or 2m, not '" + v + "'");
        opt.duration_s = *s;
      },
      "per run (default 10s)");
  app.add_option("--rounds", opt.rounds, "rounds of every variant")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--only", opt.only, "one variant")->check(CLI::IsMember({"1k", "10k"}));
  app.add_option("--cpu", opt.cpu, "pin both tools to this CPU")
      ->check(CLI::Range(0L, sysconf(_SC_NPROCESSORS_ONLN) - 1));
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) {
    return *code;
  }
  return -1;  // go on
}

/// --parse: prints what the driver would take from a recorded output (for checking the parser).
int parse_only(std::string_view kind, const std::string& path) {
  const std::string text = read_file(path);
  std::string error;
  std::optional<RunStats> stats;
  if (kind == "cyclictest") {
    if (const auto report = edm::bench::parse_cyclictest(text, error)) {
      stats = report->stats();
      fmt::print("buckets {} (0..{} us), bucketed {}, overflows {}, min {} us\n",
                 report->buckets.size(), report->buckets.size(), report->bucketed,
                 report->overflows, report->min_us);
    }
  } else if (kind == "edmplc") {
    stats = edm::bench::parse_edmplc_stats(text, error);
  } else {
    fmt::print(stderr, "edm-bench-jitter: --parse takes cyclictest or edmplc\nusage: {}\n", kUsage);
    return kExitUsage;
  }
  if (!stats) {
    fmt::print(stderr, "{}: {}\n", path, error);
    return kExitFailure;
  }
  fmt::print("cycles {}  p50 {:.1f}  p99 {:.1f}  max {:.1f} us  overruns {}  omitted {}\n",
             stats->cycles, stats->p50_us, stats->p99_us, stats->max_us, stats->overruns,
             stats->omitted_cycles);
  return 0;
}

/// The medians over rounds per variant and tool, and the edmplc/cyclictest ratios.
void print_summary(const std::vector<RunRecord>& runs) {
  fmt::print(
      "\nmedians over rounds (us; percentiles are upper bucket edges, see docs/benchmarks.md)"
      ":\n");
  fmt::print("{:<7} {:<10} {:>6} {:>12} {:>9} {:>9} {:>9}\n", "variant", "tool", "rounds",
             "cycles/run", "p50", "p99", "max");
  for (const Variant& v : kVariants) {
    RunStats pooled[2];
    for (int t = 0; t < 2; ++t) {
      const char* tool = t == 0 ? "edmplc" : "cyclictest";
      std::vector<double> cycles, p50, p99, max;
      for (const RunRecord& r : runs) {
        if (std::string_view(r.variant) == v.name && r.tool == tool) {
          cycles.push_back(static_cast<double>(r.stats.cycles));
          p50.push_back(r.stats.p50_us);
          p99.push_back(r.stats.p99_us);
          max.push_back(r.stats.max_us);
        }
      }
      if (cycles.empty()) {
        break;
      }
      pooled[t] = {static_cast<std::uint64_t>(edm::bench::median(cycles)), edm::bench::median(p50),
                   edm::bench::median(p99), edm::bench::median(max)};
      fmt::print("{:<7} {:<10} {:>6} {:>12} {:>9.1f} {:>9.1f} {:>9.1f}\n", v.name, tool,
                 cycles.size(), pooled[t].cycles, pooled[t].p50_us, pooled[t].p99_us,
                 pooled[t].max_us);
      if (t == 1) {
        fmt::print("{:<7} edmplc/cyclictest: {}; {}\n", v.name,
                   ratio_text(pooled[0].p99_us, pooled[1].p99_us, kTargetP99Ratio, "p99"),
                   ratio_text(pooled[0].max_us, pooled[1].max_us, kTargetMaxRatio, "max"));
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string_view(argv[1]) == "--parse") {
    return parse_only(argv[2], argv[3]);
  }
  Options opt;
  if (const int rc = parse_args(argc, argv, opt); rc >= 0) {
    return rc;
  }
  for (const Variant& v : kVariants) {
    if (!fs::is_regular_file(fs::path(opt.root) / v.config)) {
      fmt::print(stderr, "edm-bench-jitter: no {} under --root {}\n", v.config, opt.root);
      return kExitUsage;
    }
  }
  if (access(opt.edmplc.c_str(), X_OK) != 0) {
    fmt::print(stderr, "edm-bench-jitter: cannot run {} ({}): build it with ./edm build\n",
               opt.edmplc, std::strerror(errno));
    return kExitFailure;
  }
  opt.edmplc = fs::absolute(opt.edmplc).lexically_normal().string();
  const auto cyclictest = edm::bench::find_in_path("cyclictest");
  if (!cyclictest) {
    fmt::print(stderr,
               "edm-bench-jitter: cyclictest not found in PATH: apt-get install rt-tests "
               "(./edm bench installs it)\n");
    return kExitFailure;
  }
  TempDir tmp;
  if (tmp.path().empty()) {
    fmt::print(stderr, "edm-bench-jitter: mkdtemp under /tmp failed: {}\n", std::strerror(errno));
    return kExitFailure;
  }
  edm::bench::install_stop_handlers();

  utsname uts{};
  uname(&uts);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  fmt::print("edm bench jitter — {} — {} {} {}, {} CPUs online\n", date, uts.sysname, uts.release,
             uts.machine, sysconf(_SC_NPROCESSORS_ONLN));
  fmt::print(
      "{} s per run, {} round(s) of A=edmplc / B=cyclictest per variant, SCHED_FIFO {}, "
      "{}\n",
      opt.duration_s, opt.rounds, kFifoPriority,
      opt.cpu ? fmt::format("both pinned to CPU {}", *opt.cpu) : std::string("not pinned"));
  if (geteuid() != 0) {
    fmt::print("note: not root; both tools need the right to use SCHED_FIFO {}\n", kFifoPriority);
  }
  const int pm_qos_fd = edm::bench::hold_pm_qos();

  std::vector<RunRecord> runs;
  int rc = 0;
  for (const Variant& v : kVariants) {
    if (!opt.only.empty() && opt.only != v.name) {
      continue;
    }
    fmt::print(
        "\n{} ({} us):\n  A: {} --config {} --clock real --run-for {}s --stats-out TMP\n"
        "  B: {}\n",
        v.name, v.interval_us, opt.edmplc, (fs::path(opt.root) / v.config).string(), opt.duration_s,
        fmt::join(cyclictest_args(opt, v, *cyclictest), " "));
    std::fflush(stdout);
    for (int round = 1; round <= opt.rounds && rc == 0; ++round) {
      RunRecord a{v.name, round, "edmplc", {}, {}};
      std::string error = run_edmplc(opt, v, tmp.path(), round, a.stats, a.note);
      if (error.empty()) {
        print_run(runs.emplace_back(std::move(a)));
        RunRecord b{v.name, round, "cyclictest", {}, {}};
        error = run_cyclictest(opt, v, *cyclictest, tmp.path(), round, b.stats);
        if (error.empty()) {
          print_run(runs.emplace_back(std::move(b)));
        }
      }
      if (!error.empty()) {
        fmt::print(stderr, "edm-bench-jitter: {}\n", error);
        rc = kExitFailure;
      }
    }
    if (rc != 0) {
      break;
    }
  }
  if (pm_qos_fd >= 0) {
    close(pm_qos_fd);
  }
  if (rc != 0 || runs.empty()) {
    return kExitFailure;
  }

  print_summary(runs);
  return 0;
}
