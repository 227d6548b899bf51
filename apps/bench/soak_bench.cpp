// edm-bench-soak: the demo job in a loop on the real clock while 16 seeded random clients
// connect, subscribe, stall, disconnect and send garbage (issue 17; docs/benchmarks.md "Soak").
//   1. Baseline: edmplc + the job loop for --baseline-minutes, nobody else connected.
//   2. Soak: a fresh edmplc + the job loop for --minutes, with the hostile clients.
// Each phase samples edmplc's VmRSS and open fds every second and takes its --stats-out at SIGINT.
// --memory: one phase only, the job loop alone for --minutes (default 10), and a memory report:
// VmRSS loaded and idle, after the first job, every minute, at the end; flat or not.
// Exit: 0 all criteria PASS, 1 a criterion failed (or edmplc crashed), 2 bad arguments.
#include <arpa/inet.h>
#include <fmt/core.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <ctime>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "bench_util.hpp"
#include "edm/apps/cli.hpp"
#include "edm/apps/free_port.hpp"
#include "soak_hostile.hpp"
#include "soak_job.hpp"
#include "soak_plc.hpp"
#include "soak_report.hpp"

namespace {

namespace fs = std::filesystem;
namespace soak = edm::bench::soak;
using edm::bench::read_file;
using edm::bench::run_child;
using soak::JobRecord;
using soak::jobs_at_depth;
using soak::mem_figures;
using soak::MemFigures;
using soak::memory_report;
using soak::mib;
using soak::Phase;
using soak::TaskStats;
using soak::write_samples;
using Json = nlohmann::json;
using namespace std::chrono_literals;

constexpr int kHostileClients = 16;
constexpr long kRssKillKb = 2L << 20;  // 2 GiB: a runaway edmplc must not take the machine down
constexpr double kRssMarginFraction = 0.10;  // "flat": end ≤ ref + max(10 %, 8 MiB)
constexpr long kRssMarginKb = 8L << 10;
constexpr int kFdMargin = 2;  // "flat": quiesced end fds ≤ quiesced start fds + 2

struct Options {
  std::string root{"."};
  double minutes{30};
  double baseline_minutes{-1};  // default min(minutes, 5)
  std::uint64_t seed{1};
  int max_stall_s{60};
  std::set<std::string, std::less<>> skip;  // hostile action kinds left out (--skip a,b)
  bool memory{false};                       // --memory: the job loop alone, a memory report
};

/// Pins (trace.start candidates) and all names (var.read), from var.list over a raw socket.
void list_vars(std::uint16_t port, std::vector<std::string>& pins, std::vector<std::string>& all) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
    const std::string req =
        "{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n{\"id\":2,\"op\":\"var.list\"}\n";
    [[maybe_unused]] const auto n = ::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    std::string in;
    char buf[65536];
    for (ssize_t got; (got = ::recv(fd, buf, sizeof buf, 0)) > 0;) {
      in.append(buf, static_cast<std::size_t>(got));
      const auto at = in.find("\"id\":2");
      if (at != std::string::npos && in.find('\n', at) != std::string::npos) {
        break;
      }
    }
    std::istringstream lines(in);
    for (std::string line; std::getline(lines, line);) {
      const Json j = Json::parse(line, nullptr, false);
      if (j.is_object() && j.value("id", 0) == 2 && j.contains("vars")) {
        for (const auto& v : j["vars"]) {
          all.push_back(v.value("name", ""));
          const std::string kind = v.value("kind", "");
          if (kind == "input" || kind == "output") {
            pins.push_back(all.back());
          }
        }
      }
    }
  }
  ::close(fd);
}

std::vector<TaskStats> read_stats(const fs::path& path) {
  std::vector<TaskStats> out;
  const Json j = Json::parse(read_file(path), nullptr, false);
  if (j.is_discarded() || !j.contains("tasks")) {
    return out;
  }
  for (const auto& t : j["tasks"]) {
    out.push_back({t.value("name", ""), t.value("cycles", std::uint64_t{0}),
                   t.value("overruns", std::uint64_t{0}), t["latency_us"].value("p99", 0.0),
                   t["latency_us"].value("max", 0.0)});
  }
  return out;
}

/// "built YYYY-MM-DD HH:MM:SS, N bytes": which edmplc a phase ran (others rebuild build/ too).
std::string binary_stamp(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    return "missing";
  }
  char when[32];
  std::tm tm{};
  ::gmtime_r(&st.st_mtime, &tm);
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return fmt::format("built {}, {} bytes", when, st.st_size);
}

class Runner {
 public:
  Runner(Options o, fs::path out) : o_(std::move(o)), out_(std::move(out)) {
    edmplc_ = (fs::path(o_.root) / "build/bin/edmplc").string();
    edmhmi_ = (fs::path(o_.root) / "build/bin/edmhmi").string();
  }

  bool prepare() {
    std::string err;
    const std::string cfg =
        soak::soak_config(read_file(fs::path(o_.root) / "config/machines/drill-sim.yaml"), err);
    demo_ = read_file(fs::path(o_.root) / "examples/parts/demo.nc");
    if (cfg.empty() || demo_.empty()) {
      fmt::print(stderr, "edm-bench-soak: {}\n", err.empty() ? "cannot read demo.nc" : err);
      return false;
    }
    config_ = out_ / "drill-sim-soak.yaml";
    std::ofstream(config_) << cfg;
    // The copy includes the machines' fragments (docs/config.md "Fragments"): linked beside it.
    if (std::error_code lec; !fs::exists(out_ / "fragments", lec)) {
      fs::create_directory_symlink(fs::absolute(fs::path(o_.root) / "config/machines/fragments"),
                                   out_ / "fragments", lec);
    }
    // Copies of the two programs: build/ is shared, and a rebuild of edmhmi mid-run made its
    // binary unrunnable for seconds (jobs that never started).
    const fs::path bin = out_ / "bin";
    fs::create_directories(bin);
    std::error_code ec;
    stamp_ = "edmplc " + binary_stamp(edmplc_) + "; edmhmi " + binary_stamp(edmhmi_);
    for (std::string* exe : {&edmplc_, &edmhmi_}) {
      const fs::path copy = bin / fs::path(*exe).filename();
      fs::copy_file(*exe, copy, fs::copy_options::overwrite_existing, ec);
      if (ec) {
        fmt::print(stderr, "edm-bench-soak: cannot copy {}: {}\n", *exe, ec.message());
        return false;
      }
      *exe = copy.string();
    }
    return true;
  }

  Phase run_phase(const std::string& name, double minutes, bool hostile) {
    Phase ph;
    ph.name = name;
    const fs::path dir = out_ / name;
    std::error_code ec;
    fs::remove_all(dir, ec);  // no job files of an earlier, longer run left behind
    fs::create_directories(dir);
    const auto port = static_cast<std::uint16_t>(edm::apps::free_port());
    soak::PlcProcess plc;
    const auto t0 = soak::Clock::now();
    auto since = [t0] { return std::chrono::duration<double>(soak::Clock::now() - t0).count(); };
    fmt::print("[{}] edmplc --config {} --clock real --bridge-port {} ({} min{}); {}\n", name,
               config_.string(), port, minutes, hostile ? ", 16 hostile clients" : "", stamp_);
    std::fflush(stdout);
    const std::string started =
        plc.start({edmplc_, "--config", config_.string(), "--clock", "real", "--bridge-port",
                   std::to_string(port), "--stats-out", (dir / "stats.json").string()},
                  dir / "edmplc.log");
    if (!started.empty() || !wait_bridge(port, plc, dir)) {
      ph.crash = started.empty() ? "bridge did not come up: " + plc.exit_text() : started;
      return ph;
    }
    ph.start_q = soak::sample_proc(plc.pid()).value_or(soak::ProcSample{});
    std::vector<std::string> pins, vars;
    list_vars(port, pins, vars);

    // The sampler: 1 Hz /proc readings; a dead edmplc ends the phase (SIGTERM to ourselves makes
    // run_child() stop the running edmhmi).
    std::atomic<bool> stop_sampler{false}, plc_dead{false};
    std::mutex samples_mutex;
    std::thread sampler([&] {
      std::ofstream live(dir / "samples.csv");  // written as it goes: readable during a run
      live << "t_s,rss_kb,fds\n";
      while (!stop_sampler.load()) {
        const auto s = soak::sample_proc(plc.pid());
        if (!s || s->zombie) {
          ph.crash_t_s = since();
          plc_dead = true;
          ::kill(::getpid(), SIGTERM);
          return;
        }
        {
          std::lock_guard lock(samples_mutex);
          ph.samples.push_back(*s);
          ph.samples.back().t_s = since();
          live << fmt::format("{:.1f},{},{}", ph.samples.back().t_s, s->rss_kb, s->fds)
               << std::endl;
        }
        if (s->rss_kb > kRssKillKb) {
          ph.rss_killed = true;
          ::kill(plc.pid(), SIGKILL);
        }
        std::this_thread::sleep_for(1s);  // a 1 Hz sampling period, not a wait for an event
      }
    });

    soak::ActionLog log((dir / "hostile.log").string(), t0);
    std::atomic<bool> stop_clients{false};
    std::vector<std::thread> clients;
    if (hostile) {
      fmt::print(
          "[{}] hostile clients: seed {} (client i: mt19937_64(seed * 1000003 + i)); "
          "{} pins for trace.start\n",
          name, o_.seed, pins.size());
      for (int i = 0; i < kHostileClients; ++i) {
        soak::HostileOptions ho{i,      o_.seed * 1000003ULL + static_cast<std::uint64_t>(i),
                                port,   pins,
                                vars,   std::chrono::seconds(o_.max_stall_s),
                                o_.skip};
        clients.emplace_back(
            [ho, &log, &stop_clients] { soak::run_hostile(ho, log, stop_clients); });
      }
    }

    double worn_mm = 0;
    const double end_s = minutes * 60.0;
    for (int k = 0; since() < end_s && !plc_dead.load(); ++k) {
      JobRecord j = run_job(ph.name, dir, port, k, worn_mm, since);
      if (j.fig.electrode_left_mm) {
        worn_mm = soak::kSoakElectrodeMm - *j.fig.electrode_left_mm;
      }
      const bool interrupted = j.error == "interrupted";
      ph.jobs.push_back(std::move(j));
      if (!ph.ref) {
        std::lock_guard lock(samples_mutex);
        ph.ref = ph.samples.size();  // the next sample is the first after job 1
      }
      if (interrupted) {
        break;
      }
    }
    stop_clients = true;
    for (auto& c : clients) {
      c.join();
    }
    std::this_thread::sleep_for(3s);  // let edmplc notice the closed sockets before the reading
    stop_sampler = true;
    sampler.join();
    ph.seconds = since();
    if (!plc_dead.load() && plc.running()) {
      ph.end_q = soak::sample_proc(plc.pid()).value_or(soak::ProcSample{});
      const auto st = run_child({edmhmi_, "--port", std::to_string(port), "status"},
                                dir / "status.err", std::nullopt, 20s);
      ph.answered_at_end = st.exit_code == 0;
      std::ofstream(dir / "status-at-end.txt") << st.out;
      ph.clean_stop = plc.stop(30s);
      if (!ph.clean_stop) {
        ph.crash = "did not stop cleanly on SIGINT: " + plc.exit_text();
      }
    } else {
      plc.running();
      ph.crash = (ph.rss_killed ? "killed by the soak (VmRSS over 2 GiB); " : "") + plc.exit_text();
      report_crash(ph, log);
    }
    ph.tasks = read_stats(dir / "stats.json");
    if (hostile) {
      std::ofstream counts(dir / "hostile-actions.txt");
      for (const auto& [kind, n] : log.counts()) {
        counts << kind << " " << n << "\n";
      }
    }
    return ph;
  }

 private:
  bool wait_bridge(std::uint16_t port, soak::PlcProcess& plc, const fs::path& dir) {
    for (int i = 0; i < 100 && plc.running(); ++i) {
      const auto r = run_child({edmhmi_, "--port", std::to_string(port), "status"},
                               dir / "status.err", std::nullopt, 10s);
      if (r.exit_code == 0) {
        return true;
      }
      std::this_thread::sleep_for(100ms);  // a separate process is starting: poll it
    }
    return false;
  }

  template <class Since>
  JobRecord run_job(const std::string& name, const fs::path& dir, std::uint16_t port, int k,
                    double worn_mm, Since since) {
    JobRecord j;
    j.index = k + 1;
    j.start_s = since();
    std::string err;
    const fs::path part = dir / fmt::format("job-{:03d}.nc", k + 1);
    std::ofstream(part) << soak::job_program(demo_, k, worn_mm, err);
    for (;;) {
      const fs::path err_path = dir / fmt::format("job-{:03d}.err", k + 1);
      const auto r = run_child({edmhmi_, "--port", std::to_string(port), "run", part.string()},
                               err_path, std::nullopt, 30min);
      std::ofstream(dir / fmt::format("job-{:03d}.txt", k + 1)) << r.out;
      const std::string stderr_text = read_file(err_path);
      if (r.out.find("job report:") == std::string::npos &&
          stderr_text.find("busy") != std::string::npos && j.busy_retries < 40) {
        ++j.busy_retries;  // every session slot taken: an operator retries, as a user would
        std::this_thread::sleep_for(3s);
        continue;
      }
      j.fig = soak::parse_report(r.out);
      j.error = r.error.empty() && r.exit_code != 0 ? fmt::format("edmhmi exit {}", r.exit_code)
                                                    : r.error;
      break;
    }
    j.wall_s = since() - j.start_s;
    const auto f = j.fig;
    fmt::print(
        "[{}] job {:2d} at {:7.1f} s: {} in {:.0f} s, depth {} / {} mm, measured {} mm{}{}{}\n",
        name, j.index, j.start_s, f.outcome.empty() ? "no report" : f.outcome, j.wall_s,
        f.reached_mm ? fmt::format("{:.4f}", *f.reached_mm) : "n/a",
        f.program_mm ? fmt::format("{:.4f}", *f.program_mm) : "n/a",
        f.measured_mm ? fmt::format("{:.4f}", *f.measured_mm) : "n/a",
        f.at_depth() ? "  AT DEPTH" : "  NOT AT DEPTH",
        j.busy_retries > 0 ? fmt::format(" (operator refused busy {}x)", j.busy_retries) : "",
        j.error.empty() ? "" : " [" + j.error + "]");
    std::fflush(stdout);
    if (!f.outcome.empty() && f.outcome != "finished") {  // a fault: clear it for the next job
      run_child({edmhmi_, "--port", std::to_string(port), "reset"}, dir / "reset.err", std::nullopt,
                20s);
    }
    return j;
  }

  static void report_crash(const Phase& ph, const soak::ActionLog& log) {
    fmt::print("[{}] EDMPLC DIED at {:.1f} s: {}\n", ph.name, ph.crash_t_s, ph.crash);
    const auto tail = log.between(ph.crash_t_s - 5.0, ph.crash_t_s + 0.5);
    fmt::print("[{}] hostile actions in the 5 s before it ({}; the whole log: {}/hostile.log):\n",
               ph.name, tail.size(), ph.name);
    for (std::size_t i = tail.size() > 40 ? tail.size() - 40 : 0; i < tail.size(); ++i) {
      fmt::print("    {}\n", tail[i]);
    }
  }

  Options o_;
  fs::path out_;
  fs::path config_;
  std::string edmplc_, edmhmi_, demo_, stamp_;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app(
      "edm-bench-soak: the demo job in a loop with 16 hostile raw-socket clients "
      "(docs/benchmarks.md, Soak)",
      "edm-bench-soak");
  app.footer(
      "KIND: read_only subscribe unsubscribe trace_start trace_stop stall drain garbage_bytes "
      "bad_json deep_nesting long_line pipelined half_line close rst blank_line no_hello "
      "wrong_token");
  app.add_option("--root", o.root, "the source tree")->capture_default_str();
  app.add_option("--minutes", o.minutes, "soak length")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  app.add_option("--baseline-minutes", o.baseline_minutes,
                 "idle baseline length (default: the soak's, at most 5)")
      ->check(edm::apps::kFinite);
  app.add_option("--seed", o.seed, "the hostile clients' seed")->capture_default_str();
  app.add_option_function<std::string>(
      "--skip",
      [&](const std::string& v) {
        std::istringstream kinds(v);
        for (std::string k; std::getline(kinds, k, ',');) {
          o.skip.insert(k);
        }
      },
      "hostile kinds not run, KIND,...");
  app.add_flag("--memory", o.memory, "only the job loop for --minutes (default 10): VmRSS report");
  app.add_option("--max-stall-s", o.max_stall_s, "a job stalled longer fails the soak")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  if (const auto code = edm::apps::parse(
          app, argc, argv,
          "edm-bench-soak [--root DIR] [--minutes N] [--baseline-minutes M] [--seed S] "
          "[--max-stall-s S] [--skip KIND,...]\n       edm-bench-soak --memory [--root DIR] "
          "[--minutes N]")) {
    return *code;
  }
  if (o.memory) {
    if (app.get_option("--minutes")->count() == 0) {
      o.minutes = 10;
    }
    const fs::path out = fs::path(o.root) / "out/bench/memory";
    fs::create_directories(out);
    edm::bench::install_stop_handlers();
    fmt::print("edm-bench-soak --memory: the job loop alone for {} min; output {}\n", o.minutes,
               out.string());
    Runner runner(o, out);
    if (!runner.prepare()) {
      return 2;
    }
    return memory_report(runner.run_phase("memory", o.minutes, false), out);
  }
  if (o.baseline_minutes < 0) {
    o.baseline_minutes = std::min(o.minutes, 5.0);
  }
  const fs::path out = fs::path(o.root) / "out/bench/soak";
  fs::create_directories(out);
  edm::bench::install_stop_handlers();
  std::string skipped;
  for (const auto& k : o.skip) {
    skipped += (skipped.empty() ? "" : ",") + k;
  }
  fmt::print("edm-bench-soak: seed {}, {} min soak after a {} min idle baseline; output {}{}\n",
             o.seed, o.minutes, o.baseline_minutes, out.string(),
             skipped.empty() ? "" : "; hostile kinds skipped: " + skipped);
  Runner runner(o, out);
  if (!runner.prepare()) {
    return 2;
  }
  Phase base = runner.run_phase("baseline", o.baseline_minutes, false);
  Phase soak_ph;
  soak_ph.name = "soak";
  if (base.crash.empty()) {
    soak_ph = runner.run_phase("soak", o.minutes, true);
  } else {
    fmt::print("baseline failed ({}): the soak was not run\n", base.crash);
  }
  write_samples(out / "baseline-samples.csv", base);
  write_samples(out / "soak-samples.csv", soak_ph);

  // Verdicts.
  const MemFigures bm = mem_figures(base), sm = mem_figures(soak_ph);
  const bool alive = soak_ph.crash.empty() && soak_ph.answered_at_end && soak_ph.clean_stop;
  const bool depths = !soak_ph.jobs.empty() && jobs_at_depth(soak_ph) == soak_ph.jobs.size();
  const long rss_limit =
      sm.rss_ref_kb + std::max(kRssMarginKb, static_cast<long>(kRssMarginFraction *
                                                               static_cast<double>(sm.rss_ref_kb)));
  const bool rss_flat = alive && sm.rss_ref_kb > 0 && sm.rss_end_kb <= rss_limit;
  const bool fd_flat = alive && sm.fd_end <= sm.fd_start + kFdMargin;
  bool overruns_ok = alive && !soak_ph.tasks.empty() && soak_ph.tasks.size() == base.tasks.size();
  for (std::size_t i = 0; overruns_ok && i < soak_ph.tasks.size(); ++i) {
    const auto& b = base.tasks[i];
    const auto& s = soak_ph.tasks[i];
    // The baseline's overrun rate scaled to the soak's cycles, rounded up.
    const double allowed =
        b.cycles > 0 ? std::ceil(static_cast<double>(b.overruns) * static_cast<double>(s.cycles) /
                                 static_cast<double>(b.cycles))
                     : 0.0;
    overruns_ok = static_cast<double>(s.overruns) <= allowed;
  }
  const bool pass = alive && depths && rss_flat && fd_flat && overruns_ok;

  auto pf = [](bool ok) { return ok ? "PASS" : "FAIL"; };
  fmt::print("\nsoak summary (seed {}, {} hostile clients; jobs: demo.nc on a new hole each)\n",
             o.seed, kHostileClients);
  fmt::print("  {:<34} {:>14} {:>14}\n", "", "baseline", "soak");
  auto line = [](const std::string& what, const std::string& b, const std::string& s) {
    fmt::print("  {:<34} {:>14} {:>14}\n", what, b, s);
  };
  line("duration s", fmt::format("{:.0f}", base.seconds), fmt::format("{:.0f}", soak_ph.seconds));
  line("jobs run / at depth", fmt::format("{} / {}", base.jobs.size(), jobs_at_depth(base)),
       fmt::format("{} / {}", soak_ph.jobs.size(), jobs_at_depth(soak_ph)));
  line("VmRSS MiB start (idle)", mib(bm.rss_start_kb), mib(sm.rss_start_kb));
  line("VmRSS MiB after job 1", mib(bm.rss_ref_kb), mib(sm.rss_ref_kb));
  line("VmRSS MiB end (quiesced)", mib(bm.rss_end_kb), mib(sm.rss_end_kb));
  line("VmRSS MiB max", mib(bm.rss_max_kb), mib(sm.rss_max_kb));
  line("open fds start (idle)", std::to_string(bm.fd_start), std::to_string(sm.fd_start));
  line("open fds after job 1", std::to_string(bm.fd_ref), std::to_string(sm.fd_ref));
  line("open fds end (quiesced)", std::to_string(bm.fd_end), std::to_string(sm.fd_end));
  line("open fds max", std::to_string(bm.fd_max), std::to_string(sm.fd_max));
  for (std::size_t i = 0; i < std::max(base.tasks.size(), soak_ph.tasks.size()); ++i) {
    const TaskStats b = i < base.tasks.size() ? base.tasks[i] : TaskStats{};
    const TaskStats s = i < soak_ph.tasks.size() ? soak_ph.tasks[i] : TaskStats{};
    const std::string n = b.name.empty() ? s.name : b.name;
    line(n + " cycles", std::to_string(b.cycles), std::to_string(s.cycles));
    line(n + " overruns", std::to_string(b.overruns), std::to_string(s.overruns));
    line(n + " latency p99 / max us", fmt::format("{:.0f} / {:.0f}", b.p99_us, b.max_us),
         fmt::format("{:.0f} / {:.0f}", s.p99_us, s.max_us));
  }
  line("edmplc end", base.crash.empty() ? "clean" : "FAILED",
       soak_ph.crash.empty() ? "clean" : "FAILED");
  if (!soak_ph.crash.empty()) {
    fmt::print("  soak edmplc: {} (at {:.1f} s)\n", soak_ph.crash, soak_ph.crash_t_s);
  }
  fmt::print("  {} alive at the end, answered, stopped cleanly on SIGINT\n", pf(alive));
  fmt::print(
      "  {} every job reached its depth (|reached - program| <= {} mm, measured >= program - {} "
      "mm)\n",
      pf(depths), soak::kDepthToleranceMm, soak::kMeasuredShortMm);
  fmt::print("  {} VmRSS flat: end {} MiB <= after job 1 {} MiB + max(10 %, 8 MiB) = {} MiB\n",
             pf(rss_flat), mib(sm.rss_end_kb), mib(sm.rss_ref_kb), mib(rss_limit));
  fmt::print("  {} fds flat: end {} <= start {} + {} (both with nobody connected)\n", pf(fd_flat),
             sm.fd_end, sm.fd_start, kFdMargin);
  fmt::print("  {} RT overruns within the baseline's rate (scaled to the soak's cycles)\n",
             pf(overruns_ok));
  fmt::print("  {} soak (seed {})\n", pf(pass), o.seed);

  // JSON + CSV.
  auto phase_json = [](const Phase& ph, const MemFigures& m) {
    Json j{
        {"seconds", ph.seconds},
        {"end", ph.crash.empty() ? "clean" : ph.crash},
        {"crash_t_s", ph.crash_t_s},
        {"answered_at_end", ph.answered_at_end},
        {"clean_stop", ph.clean_stop},
        {"rss_kb",
         {{"start", m.rss_start_kb},
          {"after_job_1", m.rss_ref_kb},
          {"end", m.rss_end_kb},
          {"max", m.rss_max_kb}}},
        {"fds",
         {{"start", m.fd_start}, {"after_job_1", m.fd_ref}, {"end", m.fd_end}, {"max", m.fd_max}}}};
    for (const auto& t : ph.tasks) {
      j["tasks"].push_back({{"name", t.name},
                            {"cycles", t.cycles},
                            {"overruns", t.overruns},
                            {"latency_p99_us", t.p99_us},
                            {"latency_max_us", t.max_us}});
    }
    for (const auto& jr : ph.jobs) {
      j["jobs"].push_back({{"job", jr.index},
                           {"start_s", jr.start_s},
                           {"wall_s", jr.wall_s},
                           {"outcome", jr.fig.outcome},
                           {"reached_mm", jr.fig.reached_mm.value_or(NAN)},
                           {"program_mm", jr.fig.program_mm.value_or(NAN)},
                           {"measured_mm", jr.fig.measured_mm.value_or(NAN)},
                           {"at_depth", jr.fig.at_depth()},
                           {"busy_retries", jr.busy_retries},
                           {"error", jr.error}});
    }
    return j;
  };
  const Json summary{{"seed", o.seed},
                     {"skip", o.skip},
                     {"minutes", o.minutes},
                     {"baseline_minutes", o.baseline_minutes},
                     {"hostile_clients", kHostileClients},
                     {"baseline", phase_json(base, bm)},
                     {"soak", phase_json(soak_ph, sm)},
                     {"verdict",
                      {{"alive", alive},
                       {"depths", depths},
                       {"rss_flat", rss_flat},
                       {"fd_flat", fd_flat},
                       {"overruns", overruns_ok},
                       {"pass", pass}}}};
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";
  std::ofstream jobs(out / "jobs.csv");
  jobs
      << "phase,job,start_s,wall_s,outcome,reached_mm,program_mm,measured_mm,at_depth,busy_retries,"
         "error\n";
  for (const Phase* ph : {&base, &soak_ph}) {
    for (const auto& j : ph->jobs) {
      jobs << fmt::format("{},{},{:.1f},{:.1f},\"{}\",{:.4f},{:.4f},{:.4f},{},{},\"{}\"\n",
                          ph->name, j.index, j.start_s, j.wall_s, j.fig.outcome,
                          j.fig.reached_mm.value_or(NAN), j.fig.program_mm.value_or(NAN),
                          j.fig.measured_mm.value_or(NAN), j.fig.at_depth() ? 1 : 0, j.busy_retries,
                          j.error);
    }
  }
  fmt::print(
      "  written: {}/summary.json, jobs.csv, *-samples.csv, <phase>/hostile.log, "
      "<phase>/edmplc.log\n",
      out.string());
  return pass ? 0 : 1;
}
