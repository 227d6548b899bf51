// edm-bench-bridge: what the HMI bridge costs (docs/benchmarks.md "HMI bridge").
//  1. RT release latency of config/bench/bridge-jitter.yaml (1 kHz task) with no bridge client,
//     then with --clients clients subscribed to status at 100 Hz (p99 from --stats-out).
//  2. Command round trip (ping) on loopback, p50/p99/max, while those clients are subscribed.
//  3. Upload + commit of a 100,000-block program (blocks/s).
// Exit: 0 measured, 1 a step failed, 2 bad arguments.
#include <fmt/core.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/apps/subprocess.hpp"
#include "edm/bridge/client.hpp"

namespace {

using namespace std::chrono_literals;
using edm::bridge::Client;
using edm::bridge::ClientOptions;
using edm::bridge::Json;

struct Options {
  std::string edmplc;
  std::string root{"."};
  int duration_s{10};
  int clients{32};
  int port{7790};
  int pings{2000};
  std::size_t blocks{100'000};
};

/// edmplc with stdout and stderr into `log` (no pipe to fill up while the bench measures).
edm::apps::Process spawn(const std::vector<std::string>& args, const std::string& log) {
  edm::apps::SpawnOptions so;
  so.out = edm::apps::Stream::kFile;
  so.out_file = log;
  return edm::apps::Process(args, so);
}

/// Connects, retrying until edmplc listens (it starts in well under the deadline).
bool connect_retry(Client& c, const ClientOptions& o) {
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < end) {
    try {
      c.connect(o);
      return true;
    } catch (const edm::bridge::ClientError&) {
      std::this_thread::sleep_for(50ms);  // a separate process is starting: poll with deadline
    }
  }
  return false;
}

struct Latency {
  double p99_us{0};
  double max_us{0};
};

Latency read_latency(const std::string& stats_path) {
  std::ifstream in(stats_path);
  const Json j = Json::parse(in, nullptr, false);
  Latency l;
  if (j.is_discarded()) {
    return l;
  }
  for (const auto& t : j["tasks"]) {
    if (t["name"] == "fast") {
      l.p99_us = t["latency_us"]["p99"].get<double>();
      l.max_us = t["latency_us"]["max"].get<double>();
    }
  }
  return l;
}

double pct(std::vector<double> v, double p) {
  if (v.empty()) {
    return 0.0;
  }
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app("edm-bench-bridge: what the HMI bridge costs (docs/benchmarks.md)",
               "edm-bench-bridge");
  app.add_option("--edmplc", o.edmplc, "the edmplc binary")->required();
  app.add_option("--root", o.root, "the source tree")->capture_default_str();
  app.add_option("--duration", o.duration_s, "seconds per RT latency run")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  app.add_option("--clients", o.clients, "status subscribers")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  app.add_option("--port", o.port, "edmplc's bridge port")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  app.add_option("--blocks", o.blocks, "blocks of the uploaded program")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  if (const auto code = edm::apps::parse(app, argc, argv,
                                         "edm-bench-bridge --edmplc PATH [--root DIR] "
                                         "[--duration S] [--clients N] [--port P] [--blocks N]")) {
    return *code;
  }
  const std::string cfg = o.root + "/config/bench/bridge-jitter.yaml";
  const std::string tmp = "/tmp/edm-bench-bridge-" + std::to_string(getpid());
  const std::string run_for = std::to_string(o.duration_s) + "s";
  ClientOptions co;
  co.port = static_cast<std::uint16_t>(o.port);
  co.timeout = 10s;

  // 1a. Idle: bridge up, nobody connected.
  edm::apps::Process plc = spawn({o.edmplc, "--config", cfg, "--run-for", run_for, "--stats-out",
                                  tmp + "-idle.json", "--bridge-port", std::to_string(o.port)},
                                 tmp + "-idle.log");
  if (plc.wait() != 0) {
    fmt::print(stderr, "edmplc (idle) failed; see {}-idle.log\n", tmp);
    return 1;
  }
  const Latency idle = read_latency(tmp + "-idle.json");

  // 1b. Loaded: N subscribers at 100 Hz for the whole run, plus the ping and upload steps.
  plc = spawn({o.edmplc, "--config", cfg, "--run-for", run_for, "--stats-out", tmp + "-load.json",
               "--bridge-port", std::to_string(o.port)},
              tmp + "-load.log");
  std::vector<std::unique_ptr<Client>> subs;
  std::vector<std::unique_ptr<std::atomic<std::uint64_t>>> counts;
  std::atomic<std::uint64_t> gaps{0};
  for (int i = 0; i < o.clients; ++i) {
    subs.push_back(std::make_unique<Client>());
    counts.push_back(std::make_unique<std::atomic<std::uint64_t>>(0));
    auto* n = counts.back().get();
    auto last = std::make_shared<std::uint64_t>(0);
    subs.back()->set_event_handler([n, last, &gaps](const Json& ev) {
      const auto seq = ev.value("seq", std::uint64_t{0});
      if (*last != 0 && seq != *last + 1) {
        gaps.fetch_add(1);
      }
      *last = seq;
      n->fetch_add(1);
    });
    if (!connect_retry(*subs.back(), co) || !subs.back()->subscribe({"status"}, 100)) {
      fmt::print(stderr, "client {} could not connect/subscribe\n", i);
      plc.stop(SIGTERM);
      return 1;
    }
  }
  const auto t_sub = std::chrono::steady_clock::now();
  Client cmd;
  if (!connect_retry(cmd, co)) {
    return 1;
  }
  std::vector<double> rtt_us;
  for (int i = 0; i < o.pings; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!cmd.request("ping")) {
      fmt::print(stderr, "ping failed\n");
      return 1;
    }
    rtt_us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  }
  std::vector<edm::machining::MotionBlock> prog(o.blocks);
  for (std::size_t i = 0; i < prog.size(); ++i) {
    auto& b = prog[i];
    b.kind = i + 1 == prog.size() ? edm::machining::MotionKind::kEnd
                                  : (i % 2 == 0 ? edm::machining::MotionKind::kRapid
                                                : edm::machining::MotionKind::kLinear);
    b.line = static_cast<std::int32_t>(i + 1);
    b.col = 1;
    b.target = {static_cast<double>(i % 100) - 50.0, static_cast<double>(i % 37) - 18.0, 5.0};
    b.feed_mm_s = 5.0;
  }
  const auto u0 = std::chrono::steady_clock::now();
  const auto up = cmd.upload_program(prog);
  const double upload_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - u0).count();
  if (!up) {
    fmt::print(stderr, "upload failed: {}\n", up.message);
  }
  const int rc = plc.wait();  // runs to --run-for with the subscribers connected
  const double sub_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_sub).count();
  std::uint64_t events = 0;
  for (auto& c : counts) {
    events += c->load();
  }
  if (rc != 0) {
    fmt::print(stderr, "edmplc (loaded) exited {}; see {}-load.log\n", rc, tmp);
    return 1;
  }
  const Latency load = read_latency(tmp + "-load.json");
  fmt::print("bridge bench: {} s per run, {} clients at 100 Hz\n", o.duration_s, o.clients);
  fmt::print(
      "  RT release latency p99 (fast task, 1 kHz): idle {:.1f} us, loaded {:.1f} us "
      "(ratio {:.2f}; target <= 1.10)   max: idle {:.1f} us, loaded {:.1f} us\n",
      idle.p99_us, load.p99_us, idle.p99_us > 0 ? load.p99_us / idle.p99_us : 0.0, idle.max_us,
      load.max_us);
  fmt::print("  status events received: {} ({:.0f}/s over {:.1f} s; seq gaps: {})\n", events,
             static_cast<double>(events) / sub_s, sub_s, gaps.load());
  fmt::print("  ping round trip ({} pings, loaded): p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us\n",
             o.pings, pct(rtt_us, 0.50), pct(rtt_us, 0.99), pct(rtt_us, 1.0));
  fmt::print("  upload+commit of {} blocks: {:.3f} s = {:.0f} blocks/s ({})\n", o.blocks, upload_s,
             static_cast<double>(o.blocks) / upload_s, up ? "committed" : "FAILED");
  return up ? 0 : 1;
}
