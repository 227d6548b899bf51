// edm-bench-jitter: release jitter of edmplc as shipped against cyclictest, side by side.
//
// For each condition (idle; CPU + memory load with stress-ng on the other CPUs; bridge clients
// polling status) it alternates A = edmplc running config/bench/jitter*.yaml and B = cyclictest
// at the same SCHED_FIFO priority and period, one at a time, --rounds times, then prints every
// run and the medians over rounds with the edmplc/cyclictest ratios against the targets. The
// driver gives edmplc nothing the product lacks: no PM QoS hold (edmplc holds its own, cyclictest
// its own), no priority or affinity from outside (edmplc's tasks are pinned by their `cpu:` key,
// cyclictest's thread by -a). docs/benchmarks.md is the manual. Exit: 0 measured (even when a
// target is missed), 1 a tool failed, 2 bad arguments.

#include <fmt/core.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "bench_util.hpp"
#include "edm/apps/cli.hpp"
#include "edm/apps/free_port.hpp"
#include "jitter_load.hpp"
#include "jitter_parse.hpp"

namespace fs = std::filesystem;
using edm::bench::BridgePollers;
using edm::bench::child_failure;
using edm::bench::ChildResult;
using edm::bench::read_file;
using edm::bench::run_child;
using edm::bench::RunStats;
using edm::bench::StressLoad;
using edm::bench::tail_lines;
using edm::bench::TempDir;

namespace {

constexpr int kFifoPriority = 90;  // edmplc maps task priority p to SCHED_FIFO 90 - p
constexpr double kTargetP99Ratio = 1.1;
constexpr double kTargetMaxRatio = 1.5;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

struct Variant {
  const char* name;    // as given to --variant
  const char* config;  // relative to --root
  int interval_us;     // must match what edmplc reports for the config's fastest task
};
constexpr Variant kVariants[] = {{"1k", "config/bench/jitter.yaml", 1000},
                                 {"10k", "config/bench/jitter-10k.yaml", 100}};

constexpr const char* kConditions[] = {"idle", "load", "bridge"};

struct Options {
  std::string edmplc;
  std::string root;
  int duration_s{10};
  int rounds{5};
  std::string variant{"1k"};
  std::vector<std::string> conditions{"idle", "load", "bridge"};
  std::optional<int> cpu;  // the CPU both tools run on; default: the last one (if > 1 online)
  bool no_pin{false};
  int clients{32};
  int poll_hz{100};
};

constexpr const char* kUsage =
    "edm-bench-jitter --edmplc PATH --root DIR [--duration 10s] [--rounds 5] [--variant 1k|10k]\n"
    "                        [--conditions idle,load,bridge] [--cpu N | --no-pin]\n"
    "                        [--clients 32] [--poll-hz 100]\n"
    "       edm-bench-jitter --parse cyclictest|edmplc FILE";

/// Where and how one condition runs, shared by its A and B runs.
struct Setup {
  const Variant* variant;
  std::string condition;
  fs::path config;  // the derived config (pinned, room for the clients)
  std::string cyclictest;
  int port{0};  // bridge condition: the bridge port
};

struct RunRecord {
  std::string variant;
  std::string condition;
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
      "  {:<6} round {:<2} {:<10}  cycles {:>8}  p50 {:>8.1f}  p99 {:>8.1f}  max {:>8.1f} us"
      "{}{}\n",
      r.condition, r.round, r.tool, r.stats.cycles, r.stats.p50_us, r.stats.p99_us, r.stats.max_us,
      extra.empty() ? "" : "  ", extra);
  std::fflush(stdout);
}

std::string bridge_note(const Options& opt, std::uint64_t replies) {
  const double expected = static_cast<double>(opt.clients) * opt.poll_hz * opt.duration_s;
  return fmt::format("bridge replies {} ({:.0f} % of {} x {} Hz)", replies,
                     100.0 * static_cast<double>(replies) / expected, opt.clients, opt.poll_hz);
}

/// edmplc's "real-time:" start-up lines (what it set up for itself), without the log prefix.
std::vector<std::string> realtime_lines(const std::string& log) {
  std::vector<std::string> out;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    if (const auto at = line.find("real-time: "); at != std::string::npos) {
      const bool warn = line.find("[warning]") != std::string::npos;
      out.push_back((warn ? "WARNING " : "") + line.substr(at));
    }
  }
  return out;
}

/// One A (edmplc) run. Returns an error text, empty on success.
std::string run_edmplc(const Options& opt, const Setup& s, const fs::path& tmp, int round,
                       RunRecord& rec, std::vector<std::string>& rt_lines) {
  const std::string tag = fmt::format("{}-{}-r{}", s.variant->name, s.condition, round);
  const fs::path stats_path = tmp / ("edmplc-" + tag + ".json");
  const fs::path err_path = tmp / ("edmplc-" + tag + ".stderr");
  std::vector<std::string> args{opt.edmplc,
                                "--config",
                                s.config.string(),
                                "--clock",
                                "real",
                                "--run-for",
                                fmt::format("{}s", opt.duration_s),
                                "--stats-out",
                                stats_path.string()};
  if (s.port != 0) {
    args.insert(args.end(), {"--bridge-port", std::to_string(s.port)});
  }
  edm::apps::SpawnOptions so;
  so.out = edm::apps::Stream::kNull;
  so.err = edm::apps::Stream::kFile;
  so.err_file = err_path;
  edm::apps::Process plc(args, so);
  if (!plc.started()) {
    return "edmplc did not start: " + plc.error();
  }
  BridgePollers pollers(opt.clients, opt.poll_hz);
  if (s.port != 0) {
    if (std::string e = pollers.start(s.port); !e.empty()) {
      plc.stop(SIGINT);
      return e + "\n" + tail_lines(read_file(err_path), 15);
    }
  }
  const auto status = plc.wait(std::chrono::seconds(opt.duration_s + 60));
  pollers.stop();
  if (!status || *status != 0) {
    if (!status) {
      plc.stop(SIGKILL);
    }
    return fmt::format("edmplc failed: {}\n{}", plc.describe(),
                       tail_lines(read_file(err_path), 15));
  }
  if (s.port != 0) {
    rec.note = bridge_note(opt, pollers.replies());
  }
  std::string error;
  const auto parsed = edm::bench::parse_edmplc_stats(read_file(stats_path), error);
  if (!parsed) {
    return fmt::format("edmplc: cannot use {}: {}", stats_path.string(), error);
  }
  if (parsed->interval_us != s.variant->interval_us) {
    return fmt::format("edmplc: {}'s fastest task runs every {} us, the {} variant needs {} us",
                       s.variant->config, parsed->interval_us, s.variant->name,
                       s.variant->interval_us);
  }
  rec.stats = *parsed;
  const std::string log = read_file(err_path);
  rt_lines = realtime_lines(log);
  // DESIGN §6: without the right to use SCHED_FIFO edmplc warns and runs SCHED_OTHER.
  if (log.find("SCHED_FIFO refused") != std::string::npos) {
    rec.note += (rec.note.empty() ? "" : "; ") + std::string("WARNING: edmplc ran SCHED_OTHER");
  }
  return {};
}

/// The cyclictest command line: same FIFO priority and period as edmplc's fast task.
std::vector<std::string> cyclictest_args(const Options& opt, const Setup& s) {
  // 1 us buckets up to 2 periods (at least 1 ms); later samples count as overflows (and max).
  const int hist_max_us = std::max(1000, 2 * s.variant->interval_us);
  std::vector<std::string> args{s.cyclictest, "-m", "-q", "--policy=fifo"};
  args.insert(args.end(),
              {"-p", std::to_string(kFifoPriority), "-i", std::to_string(s.variant->interval_us)});
  args.insert(args.end(), {"-D", std::to_string(opt.duration_s), "-t", "1"});
  args.insert(args.end(), {"-h", std::to_string(hist_max_us)});
  if (opt.cpu) {
    args.insert(args.end(), {"-a", std::to_string(*opt.cpu)});
  }
  return args;
}

/// One B (cyclictest) run. In the bridge condition the clients poll an edmplc on the virtual
/// clock (one SCHED_OTHER thread, paced to wall time, no RT threads, no PM QoS request), so
/// cyclictest runs beside the same bridge traffic. Returns an error text, empty on success.
std::string run_cyclictest(const Options& opt, const Setup& s, const fs::path& tmp, int round,
                           RunRecord& rec) {
  const std::string tag = fmt::format("{}-{}-r{}", s.variant->name, s.condition, round);
  const fs::path err_path = tmp / ("cyclictest-" + tag + ".stderr");
  std::optional<edm::apps::Process> server;
  BridgePollers pollers(opt.clients, opt.poll_hz);
  if (s.port != 0) {
    edm::apps::SpawnOptions so;
    so.out = edm::apps::Stream::kNull;
    so.err = edm::apps::Stream::kFile;
    so.err_file = tmp / ("server-" + tag + ".stderr");
    server.emplace(
        std::vector<std::string>{opt.edmplc, "--config", s.config.string(), "--clock", "virtual",
                                 "--speed", "1", "--bridge-port", std::to_string(s.port)},
        so);
    if (std::string e = pollers.start(s.port); !e.empty()) {
      return e + "\n" + tail_lines(read_file(so.err_file), 15);
    }
  }
  const ChildResult r = run_child(cyclictest_args(opt, s), err_path, std::nullopt,
                                  std::chrono::seconds(opt.duration_s + 60));
  if (s.port != 0) {
    rec.note = bridge_note(opt, pollers.replies());
    pollers.stop();
    server->stop(SIGINT, std::chrono::milliseconds(5000));
  }
  if (auto failure = child_failure("cyclictest", r, err_path); !failure.empty()) {
    return failure;
  }
  std::string error;
  const auto report = edm::bench::parse_cyclictest(r.out, error);
  if (!report) {
    return fmt::format("cyclictest: cannot parse its output: {}\n{}", error, tail_lines(r.out, 8));
  }
  rec.stats = report->stats();
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
      "edm-bench-jitter: release jitter of edmplc as shipped against cyclictest "
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
  app.add_option("--rounds", opt.rounds, "A/B rounds per condition")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--variant", opt.variant, "the task period: 1k (1 ms) or 10k (100 us)")
      ->check(CLI::IsMember({"1k", "10k"}))
      ->capture_default_str();
  app.add_option("--conditions", opt.conditions, "any of idle, load, bridge")
      ->delimiter(',')
      ->check(CLI::IsMember({"idle", "load", "bridge"}));
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  auto* cpu = app.add_option("--cpu", opt.cpu, "the CPU both tools run on (default: the last)")
                  ->check(CLI::Range(0L, cpus - 1));
  app.add_flag("--no-pin", opt.no_pin, "pin neither tool")->excludes(cpu);
  app.add_option("--clients", opt.clients, "bridge condition: clients polling status")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--poll-hz", opt.poll_hz, "bridge condition: requests per client per second")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) {
    return *code;
  }
  if (!opt.cpu && !opt.no_pin && cpus > 1) {
    opt.cpu = static_cast<int>(cpus - 1);
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

/// Median of one statistic over the rounds of a condition and tool.
RunStats pooled(const std::vector<RunRecord>& runs, const std::string& condition,
                const std::string& tool, std::size_t& n) {
  std::vector<double> cycles, p50, p99, max;
  for (const RunRecord& r : runs) {
    if (r.condition == condition && r.tool == tool) {
      cycles.push_back(static_cast<double>(r.stats.cycles));
      p50.push_back(r.stats.p50_us);
      p99.push_back(r.stats.p99_us);
      max.push_back(r.stats.max_us);
    }
  }
  n = cycles.size();
  return {static_cast<std::uint64_t>(edm::bench::median(cycles)), edm::bench::median(p50),
          edm::bench::median(p99), edm::bench::median(max)};
}

/// The medians over rounds per condition and tool, and the edmplc/cyclictest ratios.
void print_summary(const Options& opt, const std::vector<RunRecord>& runs) {
  fmt::print(
      "\nmedians over rounds, {} (us; percentiles are upper bucket edges, see "
      "docs/benchmarks.md):\n",
      opt.variant);
  fmt::print(
      "| condition | tool | rounds | cycles/run | p50 | p99 | max | p99 ratio | max ratio |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  std::string verdicts;
  for (const std::string& c : opt.conditions) {
    std::size_t na = 0, nb = 0;
    const RunStats a = pooled(runs, c, "edmplc", na);
    const RunStats b = pooled(runs, c, "cyclictest", nb);
    if (na == 0 || nb == 0) {
      continue;
    }
    const double p99r = b.p99_us > 0 ? a.p99_us / b.p99_us : 0.0;
    const double maxr = b.max_us > 0 ? a.max_us / b.max_us : 0.0;
    fmt::print("| {} | edmplc | {} | {} | {:.1f} | {:.1f} | {:.1f} | **{:.2f}** | **{:.2f}** |\n",
               c, na, a.cycles, a.p50_us, a.p99_us, a.max_us, p99r, maxr);
    fmt::print("| | cyclictest | {} | {} | {:.1f} | {:.1f} | {:.1f} | | |\n", nb, b.cycles,
               b.p50_us, b.p99_us, b.max_us);
    verdicts += fmt::format("{:<7} edmplc/cyclictest: {}; {}\n", c,
                            ratio_text(a.p99_us, b.p99_us, kTargetP99Ratio, "p99"),
                            ratio_text(a.max_us, b.max_us, kTargetMaxRatio, "max"));
  }
  fmt::print("\n{}", verdicts);
}

std::string first_line_of(const fs::path& path, std::string_view key) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) == 0) {
      const auto colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(colon + 2);
    }
  }
  return "?";
}

std::string load_average() {
  std::string text = read_file("/proc/loadavg");
  return text.substr(0, text.find(' ', text.find(' ', text.find(' ') + 1) + 1));
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
  const Variant* variant = nullptr;
  for (const Variant& v : kVariants) {
    if (opt.variant == v.name) {
      variant = &v;
    }
  }
  if (!fs::is_regular_file(fs::path(opt.root) / variant->config)) {
    fmt::print(stderr, "edm-bench-jitter: no {} under --root {}\n", variant->config, opt.root);
    return kExitUsage;
  }
  if (access(opt.edmplc.c_str(), X_OK) != 0) {
    fmt::print(stderr, "edm-bench-jitter: cannot run {} ({}): build it with ./edm build\n",
               opt.edmplc, std::strerror(errno));
    return kExitFailure;
  }
  opt.edmplc = fs::absolute(opt.edmplc).lexically_normal().string();
  const auto cyclictest = edm::bench::find_in_path("cyclictest");
  const auto stress_ng = edm::bench::find_in_path("stress-ng");
  if (!cyclictest || !stress_ng) {
    fmt::print(stderr,
               "edm-bench-jitter: {} not found in PATH: apt-get install {} (./edm bench "
               "installs it)\n",
               !cyclictest ? "cyclictest" : "stress-ng", !cyclictest ? "rt-tests" : "stress-ng");
    return kExitFailure;
  }
  TempDir tmp;
  if (tmp.path().empty()) {
    fmt::print(stderr, "edm-bench-jitter: mkdtemp under /tmp failed: {}\n", std::strerror(errno));
    return kExitFailure;
  }
  edm::bench::install_stop_handlers();

  // The config as a user pins it: `cpu:` on every task, and room for the bridge clients.
  std::string error;
  const auto derived = edm::bench::pinned_config(read_file(fs::path(opt.root) / variant->config),
                                                 opt.cpu, opt.clients + 8, error);
  if (!derived) {
    fmt::print(stderr, "edm-bench-jitter: {}: {}\n", variant->config, error);
    return kExitFailure;
  }
  const fs::path config = tmp.path() / fs::path(variant->config).filename();
  std::ofstream(config) << *derived;

  utsname uts{};
  uname(&uts);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  fmt::print("edm bench jitter — {} — {} {} {}, {} CPUs online ({}), load average {}\n", date,
             uts.sysname, uts.release, uts.machine, cpus,
             first_line_of("/proc/cpuinfo", "model name"), load_average());
  std::string others;  // the CPUs stress-ng loads: every CPU but the tools' one
  for (long c = 0; c < cpus; ++c) {
    if (!opt.cpu || c != *opt.cpu || cpus == 1) {
      others += (others.empty() ? "" : ",") + std::to_string(c);
    }
  }
  fmt::print(
      "{} s per run, {} round(s) of A=edmplc / B=cyclictest per condition, SCHED_FIFO {}, {}\n",
      opt.duration_s, opt.rounds, kFifoPriority,
      opt.cpu ? fmt::format("both on CPU {} (edmplc: `cpu: {}` on its tasks; cyclictest -a {})",
                            *opt.cpu, *opt.cpu, *opt.cpu)
              : std::string("not pinned"));
  fmt::print(
      "  A: {} --config {} (jitter config + cpu: + bridge max_sessions) --clock real "
      "--run-for {}s --stats-out TMP\n  B: {}\n",
      opt.edmplc, variant->config, opt.duration_s,
      fmt::join(cyclictest_args(opt, {variant, "", config, *cyclictest, 0}), " "));
  if (geteuid() != 0) {
    fmt::print("note: not root; both tools need the right to use SCHED_FIFO {}\n", kFifoPriority);
  }

  std::vector<RunRecord> runs;
  std::vector<std::string> rt_lines;
  int rc = 0;
  for (const std::string& condition : opt.conditions) {
    Setup s{variant, condition, config, *cyclictest,
            condition == "bridge" ? edm::apps::free_port() : 0};
    std::optional<StressLoad> stress;
    fmt::print("\n{}: ", condition);
    if (condition == "idle") {
      fmt::print("nothing else running\n");
    } else if (condition == "load") {
      const int workers =
          std::max<int>(1, static_cast<int>(std::count(others.begin(), others.end(), ',')) + 1);
      stress.emplace(*stress_ng, others, workers, (tmp.path() / "stress-ng.log").string());
      fmt::print("{}\n", stress->command());
    } else {
      fmt::print(
          "{} bridge clients polling status at {} Hz (B: beside an edmplc on the virtual "
          "clock, paced 1x)\n",
          opt.clients, opt.poll_hz);
    }
    std::fflush(stdout);
    for (int round = 1; round <= opt.rounds && rc == 0; ++round) {
      if (stress) {
        if (std::string f = stress->failure(); !f.empty()) {
          fmt::print(stderr, "edm-bench-jitter: {}\n", f);
          rc = kExitFailure;
          break;
        }
      }
      RunRecord a{variant->name, condition, round, "edmplc", {}, {}};
      std::vector<std::string> lines;
      error = run_edmplc(opt, s, tmp.path(), round, a, lines);
      if (error.empty()) {
        if (rt_lines.empty()) {
          rt_lines = lines;
          fmt::print("  edmplc set up for itself (its start-up lines, first run):\n");
          for (const std::string& l : rt_lines) {
            fmt::print("    {}\n", l);
          }
        }
        print_run(runs.emplace_back(std::move(a)));
        RunRecord b{variant->name, condition, round, "cyclictest", {}, {}};
        error = run_cyclictest(opt, s, tmp.path(), round, b);
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
  if (rc != 0 || runs.empty()) {
    return kExitFailure;
  }
  print_summary(opt, runs);
  fmt::print("load average at the end: {}\n", load_average());
  return 0;
}
