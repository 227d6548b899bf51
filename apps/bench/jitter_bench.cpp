// edm-bench-jitter: release jitter of edmplc against cyclictest, side by side in one run.
//
// For each variant (1 kHz, 10 kHz) it alternates A = edmplc running config/bench/jitter*.yaml and
// B = cyclictest at the same SCHED_FIFO priority and period, one at a time, --rounds times, then
// prints every run and the medians over rounds with the edmplc/cyclictest ratios against the
// targets. docs/benchmarks.md is the manual. Exit: 0 measured (even when a target is missed),
// 1 a tool failed, 2 bad arguments.

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "jitter_parse.hpp"

namespace fs = std::filesystem;
using edm::bench::RunStats;

namespace {

constexpr int kFifoPriority = 90;  // edmplc maps task priority p to SCHED_FIFO 90 - p
constexpr double kTargetP99Ratio = 1.2;
constexpr double kTargetMaxRatio = 2.0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int /*sig*/) { g_stop = 1; }

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
    "usage: edm-bench-jitter --edmplc PATH --root DIR [--duration 10s] [--rounds 2]\n"
    "                        [--only 1k|10k] [--cpu N]\n"
    "       edm-bench-jitter --parse cyclictest|edmplc FILE   (print the stats parsed from a\n"
    "                        recorded cyclictest -h output or edmplc --stats-out file)\n";

/// Removes the mkdtemp directory (and the stats/stderr files in it) when main returns.
class TempDir {
 public:
  TempDir() {
    std::string templ = (fs::temp_directory_path() / "edm-bench-jitter.XXXXXX").string();
    if (mkdtemp(templ.data()) != nullptr) {
      path_ = templ;
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) {
      fs::remove_all(path_, ec);
    }
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The last `n` lines of `text`, indented, for error messages.
std::string tail_lines(const std::string& text, std::size_t n) {
  std::size_t pos = text.size();
  while (pos > 0 && text[pos - 1] == '\n') {
    --pos;
  }
  std::size_t start = pos;
  for (std::size_t lines = 0; start > 0 && lines < n; --start) {
    if (text[start - 1] == '\n' && ++lines == n) {
      break;
    }
  }
  std::string out;
  std::istringstream in(text.substr(start, pos - start));
  for (std::string line; std::getline(in, line);) {
    out += "    | " + line + "\n";
  }
  return out;
}

std::optional<std::string> find_in_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (access(candidate.c_str(), X_OK) == 0) {
      return candidate.string();
    }
  }
  return std::nullopt;
}

struct ChildResult {
  std::string error;  // non-empty: could not start, timed out or interrupted
  int exit_code{-1};  // >= 0 when the child exited normally
  int signal{0};      // the signal that ended it, if any
  std::string out;    // its stdout
};

/// Makes `fd` become `target` in the child. dup2(fd, fd) would keep FD_CLOEXEC set.
void move_fd(int fd, int target) {
  if (fd == target) {
    fcntl(target, F_SETFD, 0);
  } else {
    dup2(fd, target);
  }
}

/// Runs argv[0] (an absolute path; no shell) with stdin from /dev/null, stdout into a pipe we
/// read, stderr into `err_path`, optionally pinned with all its threads to `cpu`. Kills it
/// (SIGTERM, then SIGKILL) after `timeout` or when we get SIGINT/SIGTERM.
ChildResult run_child(const std::vector<std::string>& args, const fs::path& err_path,
                      std::optional<int> cpu, std::chrono::seconds timeout) {
  ChildResult result;
  std::vector<char*> argv;
  for (const auto& a : args) {
    argv.push_back(const_cast<char*>(a.c_str()));
  }
  argv.push_back(nullptr);
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (cpu) {
    CPU_SET(static_cast<std::size_t>(*cpu), &cpus);
  }
  int out_pipe[2] = {-1, -1};
  int exec_pipe[2] = {-1, -1};  // carries the child's errno if exec fails; EOF on success
  const int err_fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  const int null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (err_fd < 0 || null_fd < 0 || pipe2(out_pipe, O_CLOEXEC) != 0 ||
      pipe2(exec_pipe, O_CLOEXEC) != 0) {
    result.error = fmt::format("cannot set up pipes/files: {}", std::strerror(errno));
    for (const int fd : {err_fd, null_fd, out_pipe[0], out_pipe[1], exec_pipe[0], exec_pipe[1]}) {
      if (fd >= 0) {
        close(fd);
      }
    }
    return result;
  }
  const pid_t pid = fork();
  if (pid == 0) {  // child: async-signal-safe calls only
    move_fd(null_fd, STDIN_FILENO);
    move_fd(out_pipe[1], STDOUT_FILENO);
    move_fd(err_fd, STDERR_FILENO);
    if (!cpu || sched_setaffinity(0, sizeof cpus, &cpus) == 0) {
      execv(argv[0], argv.data());
    }
    const int err = errno;
    [[maybe_unused]] const ssize_t n = write(exec_pipe[1], &err, sizeof err);
    _exit(127);
  }
  close(out_pipe[1]);
  close(exec_pipe[1]);
  close(err_fd);
  close(null_fd);
  if (pid < 0) {
    result.error = fmt::format("fork: {}", std::strerror(errno));
    close(out_pipe[0]);
    close(exec_pipe[0]);
    return result;
  }
  int child_errno = 0;
  ssize_t got = 0;
  do {
    got = read(exec_pipe[0], &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR);
  close(exec_pipe[0]);
  if (got == static_cast<ssize_t>(sizeof child_errno)) {
    result.error = fmt::format("cannot run {}: {}", args[0], std::strerror(child_errno));
  }

  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool eof = !result.error.empty();
  bool killed = false;
  int status = 0;
  char buf[4096];
  for (;;) {
    if (!killed && (g_stop != 0 || std::chrono::steady_clock::now() > deadline)) {
      if (result.error.empty()) {
        result.error = g_stop != 0 ? "interrupted" : fmt::format("no exit after {} s", timeout.count());
      }
      kill(pid, SIGTERM);
      killed = true;
      for (int i = 0; i < 200 && waitpid(pid, &status, WNOHANG) == 0; ++i) {
        usleep(10'000);
      }
      kill(pid, SIGKILL);  // harmless if it already exited: it is a zombie until waitpid below
      break;
    }
    if (eof) {
      const pid_t done = waitpid(pid, &status, WNOHANG);
      if (done == pid) {
        break;
      }
      usleep(10'000);
      continue;
    }
    pollfd pfd{out_pipe[0], POLLIN, 0};
    if (poll(&pfd, 1, 100) <= 0) {
      continue;  // timeout or EINTR: check the deadline and the stop flag
    }
    const ssize_t n = read(out_pipe[0], buf, sizeof buf);
    if (n > 0) {
      result.out.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      eof = true;
    }
  }
  close(out_pipe[0]);
  if (killed) {
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

/// Empty when the child ran and exited 0; otherwise what went wrong, with its stderr's tail.
std::string child_failure(const std::string& tool, const ChildResult& r, const fs::path& err) {
  std::string what;
  if (!r.error.empty()) {
    what = r.error;
  } else if (r.signal != 0) {
    what = fmt::format("killed by signal {} ({})", r.signal, strsignal(r.signal));
  } else if (r.exit_code != 0) {
    what = fmt::format("exit code {}", r.exit_code);
  } else {
    return {};
  }
  return fmt::format("{} failed: {}\n{}{}", tool, what, tail_lines(read_file(err), 15),
                     tail_lines(r.out, 5));
}

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
  fmt::print("  {:<4} round {:<2} {:<10}  cycles {:>8}  p50 {:>8.1f}  p99 {:>8.1f}  max {:>8.1f} us"
             "  {}\n",
             r.variant, r.round, r.tool, r.stats.cycles, r.stats.p50_us, r.stats.p99_us,
             r.stats.max_us, extra);
  std::fflush(stdout);
}

/// One A (edmplc) run. Returns an error text, empty on success.
std::string run_edmplc(const Options& opt, const Variant& v, const fs::path& tmp, int round,
                       RunStats& stats, std::string& note) {
  const fs::path stats_path = tmp / fmt::format("edmplc-{}-r{}.json", v.name, round);
  const fs::path err_path = tmp / fmt::format("edmplc-{}-r{}.stderr", v.name, round);
  const std::vector<std::string> args = {opt.edmplc,
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

/// One B (cyclictest) run; `command` receives the command line for the report.
std::string run_cyclictest(const Options& opt, const Variant& v, const std::string& cyclictest,
                           const fs::path& tmp, int round, RunStats& stats, std::string& command) {
  const int hist_max_us = std::max(1000, 2 * v.interval_us);
  std::vector<std::string> args = {cyclictest,
                                   "-m",
                                   "-q",
                                   "--policy=fifo",
                                   "-p",
                                   std::to_string(kFifoPriority),
                                   "-i",
                                   std::to_string(v.interval_us),
                                   "-D",
                                   std::to_string(opt.duration_s),
                                   "-t",
                                   "1",
                                   "-h",
                                   std::to_string(hist_max_us)};
  if (opt.cpu) {
    args.insert(args.end(), {"-a", std::to_string(*opt.cpu)});
  }
  command.clear();
  for (const auto& a : args) {
    command += (command.empty() ? "" : " ") + a;
  }
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

/// Holds /dev/cpu_dma_latency at 0 us for the whole bench (released when the fd closes), so both
/// tools run with the same C-state limit: cyclictest sets it by itself, edmplc does not.
int hold_pm_qos() {
  const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  const std::int32_t zero = 0;
  if (fd < 0 || write(fd, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
    fmt::print("note: cannot hold /dev/cpu_dma_latency at 0 us ({}): edmplc may see deeper "
               "C-states than cyclictest, which sets it itself\n",
               std::strerror(errno));
    if (fd >= 0) {
      close(fd);
    }
    return -1;
  }
  return fd;
}

std::string ratio_text(double num, double den, double target, const char* what) {
  if (den <= 0.0) {
    return fmt::format("{} ratio n/a (cyclictest 0)", what);
  }
  const double ratio = num / den;
  return fmt::format("{} {:.2f} (target <= {:.1f}) {}", what, ratio, target,
                     ratio <= target ? "PASS" : "MISS");
}

int parse_args(int argc, char** argv, Options& opt) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view flag = args[i];
    if (flag == "--help" || flag == "-h") {
      fmt::print("{}", kUsage);
      return 0;
    }
    if (i + 1 >= args.size()) {
      fmt::print(stderr, "edm-bench-jitter: {} needs a value\n{}", flag, kUsage);
      return kExitUsage;
    }
    const std::string value(args[++i]);
    bool ok = true;
    if (flag == "--edmplc") {
      opt.edmplc = value;
    } else if (flag == "--root") {
      opt.root = value;
    } else if (flag == "--duration") {
      const auto s = edm::bench::parse_seconds(value);
      ok = s.has_value();
      opt.duration_s = s.value_or(0);
    } else if (flag == "--rounds") {
      const auto n = edm::bench::parse_uint(value);
      ok = n && *n >= 1 && *n <= 100;
      opt.rounds = static_cast<int>(n.value_or(0));
    } else if (flag == "--only") {
      ok = value == "1k" || value == "10k";
      opt.only = value;
    } else if (flag == "--cpu") {
      const auto n = edm::bench::parse_uint(value);
      const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
      ok = n && static_cast<long>(*n) < ncpu;
      opt.cpu = static_cast<int>(n.value_or(0));
    } else {
      fmt::print(stderr, "edm-bench-jitter: unknown option '{}'\n{}", flag, kUsage);
      return kExitUsage;
    }
    if (!ok) {
      fmt::print(stderr,
                 "edm-bench-jitter: bad value '{}' for {} (duration: whole seconds as 10s or "
                 "2m; rounds: 1..100; only: 1k or 10k; cpu: an online CPU number)\n",
                 value, flag);
      return kExitUsage;
    }
  }
  if (opt.edmplc.empty() || opt.root.empty()) {
    fmt::print(stderr, "edm-bench-jitter: --edmplc and --root are required\n{}", kUsage);
    return kExitUsage;
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
    fmt::print(stderr, "{}", kUsage);
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
  opt.edmplc = fs::absolute(opt.edmplc).string();
  const auto cyclictest = find_in_path("cyclictest");
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
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;  // no SA_RESTART: poll() returns EINTR and we stop the child
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  utsname uts{};
  uname(&uts);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  fmt::print("edm bench jitter — {} — {} {} {}, {} CPUs online\n", date, uts.sysname, uts.release,
             uts.machine, sysconf(_SC_NPROCESSORS_ONLN));
  fmt::print("{} s per run, {} round(s) of A=edmplc / B=cyclictest per variant, SCHED_FIFO {}, "
             "{}\n",
             opt.duration_s, opt.rounds, kFifoPriority,
             opt.cpu ? fmt::format("both pinned to CPU {}", *opt.cpu) : std::string("not pinned"));
  if (geteuid() != 0) {
    fmt::print("note: not root; both tools need the right to use SCHED_FIFO {}\n", kFifoPriority);
  }
  const int pm_qos_fd = hold_pm_qos();

  std::vector<RunRecord> runs;
  std::string cyclictest_command;
  int rc = 0;
  for (const Variant& v : kVariants) {
    if (!opt.only.empty() && opt.only != v.name) {
      continue;
    }
    fmt::print("\n{} ({} us, {}):\n", v.name, v.interval_us, v.config);
    for (int round = 1; round <= opt.rounds && rc == 0; ++round) {
      RunRecord a{v.name, round, "edmplc", {}, {}};
      std::string error = run_edmplc(opt, v, tmp.path(), round, a.stats, a.note);
      if (error.empty()) {
        print_run(runs.emplace_back(std::move(a)));
        RunRecord b{v.name, round, "cyclictest", {}, {}};
        error = run_cyclictest(opt, v, *cyclictest, tmp.path(), round, b.stats,
                               cyclictest_command);
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

  fmt::print("\ncyclictest command: {}\n", cyclictest_command);
  fmt::print("medians over rounds (us; percentiles are upper bucket edges, see docs/benchmarks.md)"
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
  return 0;
}
