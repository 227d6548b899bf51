// edm-bench-fleet (./edm bench fleet, docs/benchmarks.md "Fleet over MQTT"): one process publishing
// as N Sparkplug B edge nodes (the same EdgeNode edmplc's telemetry uses, one MQTT connection
// each) to a Debian mosquitto it starts on a free loopback port, and one subscriber on spBv1.0/#
// measuring what arrives: messages per second, latency (publish → delivery, system clock, same
// host) and losses (seq gaps). Rates are swept per node until the broker no longer keeps up.

#include <mosquitto.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/apps/free_port.hpp"
#include "edm/sparkplug/edge_node.hpp"
#include "edm/sparkplug/sparkplug.hpp"

namespace {

namespace sp = edm::sparkplug;
using Clock = std::chrono::steady_clock;

std::uint64_t now_us() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// CPU seconds (user + system) of a process, from /proc/PID/stat.
double cpu_s(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string s((std::istreambuf_iterator<char>(in)), {});
  const auto close = s.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::vector<std::string> f;
  std::string cur;
  for (char c : s.substr(close + 2)) {
    if (c == ' ') {
      f.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (f.size() < 13) return 0.0;
  return static_cast<double>(std::stoull(f[11]) + std::stoull(f[12])) /
         static_cast<double>(sysconf(_SC_CLK_TCK));
}

struct Sink {
  std::mutex mu;
  std::vector<double> latency_ms;
  std::uint64_t received{0};
  std::uint64_t gaps{0};
  std::vector<int> last_seq;  // per node index, -1 = none
};

void on_message(mosquitto*, void* user, const mosquitto_message* m) {
  auto* sink = static_cast<Sink*>(user);
  const std::uint64_t t = now_us();
  const auto topic = sp::parse_topic(m->topic);
  if (!topic || topic->type != sp::MessageType::kDData) return;
  const auto p = sp::decode(std::string_view(static_cast<const char*>(m->payload),
                                             static_cast<std::size_t>(m->payloadlen)));
  if (!p) return;
  const sp::Metric* sent = p->find("bench/sent_us");
  std::lock_guard lock(sink->mu);
  ++sink->received;
  if (sent != nullptr) {
    const double us = sp::as_double(sent->value).value_or(0.0);
    sink->latency_ms.push_back((static_cast<double>(t) - us) / 1000.0);
  }
  const std::size_t idx = static_cast<std::size_t>(std::stoul(topic->node.substr(5)));
  if (idx < sink->last_seq.size() && p->seq) {
    const int s = static_cast<int>(*p->seq);
    // DDATA only here (NDATA also takes seq numbers): a gap is a jump of more than a heartbeat.
    if (sink->last_seq[idx] >= 0 && (s - sink->last_seq[idx] + 256) % 256 > 2) ++sink->gaps;
    sink->last_seq[idx] = s;
  }
}

double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  int nodes = 50;
  double seconds = 5.0;
  std::vector<double> rates{1, 10, 50, 100, 200, 400};
  int metrics = 10;
  bool nodelay = false;
  CLI::App app("edm-bench-fleet: N Sparkplug B nodes against one mosquitto (docs/benchmarks.md)",
               "edm-bench-fleet");
  app.add_option("--nodes", nodes, "edge nodes (one MQTT connection each)")
      ->check(CLI::Range(1, 2000));
  app.add_option("--seconds", seconds, "per rate step")->check(CLI::Range(1.0, 600.0));
  app.add_option("--rates", rates, "DDATA per second per node, swept");
  app.add_option("--metrics", metrics, "changing Double metrics per DDATA")
      ->check(CLI::Range(1, 64));
  app.add_flag("--broker-nodelay", nodelay, "mosquitto's set_tcp_nodelay true (default: false)");
  if (const auto code = edm::apps::parse(app, argc, argv, "edm-bench-fleet [--nodes N] ...")) {
    return *code;
  }

  const auto dir =
      std::filesystem::temp_directory_path() / ("edm-bench-fleet-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const int port = edm::apps::free_port();
  {
    std::ofstream conf(dir / "mosquitto.conf");
    conf << "listener " << port << " 127.0.0.1\nallow_anonymous true\npersistence false\n"
         << "max_queued_messages 1000\n"
         << (nodelay ? "set_tcp_nodelay true\n" : "");
  }
  const pid_t broker = fork();
  if (broker == 0) {
    const std::string conf = (dir / "mosquitto.conf").string();
    const std::string log = (dir / "mosquitto.log").string();
    if (std::freopen(log.c_str(), "w", stderr) == nullptr) _exit(127);
    execlp("mosquitto", "mosquitto", "-c", conf.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  std::string version = "mosquitto";
  {
    int major = 0, minor = 0, rev = 0;
    mosquitto_lib_version(&major, &minor, &rev);
    version += " (libmosquitto " + std::to_string(major) + "." + std::to_string(minor) + "." +
               std::to_string(rev) + ")";
  }

  Sink sink;
  sink.last_seq.assign(static_cast<std::size_t>(nodes), -1);
  mosquitto_lib_init();
  mosquitto* sub = mosquitto_new("bench-sub", true, &sink);
  mosquitto_message_callback_set(sub, on_message);
  if (mosquitto_connect(sub, "127.0.0.1", port, 30) != MOSQ_ERR_SUCCESS) {
    std::fprintf(stderr, "edm-bench-fleet: cannot connect to mosquitto on %d\n", port);
    kill(broker, SIGTERM);
    return 1;
  }
  mosquitto_subscribe(sub, nullptr, "spBv1.0/#", 0);
  mosquitto_loop_start(sub);

  std::vector<std::unique_ptr<sp::EdgeNode>> fleet;
  std::vector<sp::MetricDef> defs;
  defs.push_back({"bench/sent_us", sp::DataType::kUInt64, 0.0});
  for (int m = 0; m < metrics; ++m)
    defs.push_back({"m" + std::to_string(m), sp::DataType::kDouble, 0.0});
  for (int i = 0; i < nodes; ++i) {
    sp::EdgeNodeOptions o;
    o.port = port;
    o.group = "bench";
    o.node = "node-" + std::to_string(i);
    o.device = "edm";
    o.device_metrics = defs;
    o.heartbeat = std::chrono::milliseconds(0);
    fleet.push_back(std::make_unique<sp::EdgeNode>(o, nullptr));
    fleet.back()->start();
  }
  std::vector<sp::Value> values(defs.size());
  const auto tick_all = [&](std::uint64_t k) {
    for (auto& n : fleet) {
      values[0] = now_us();
      for (std::size_t m = 1; m < values.size(); ++m)
        values[m] = static_cast<double>(k) + 0.001 * static_cast<double>(m);
      n->tick(values, sp::now_ms());
    }
  };
  // Births: wait until every node is connected and has published them.
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  std::uint64_t k = 0;
  while (Clock::now() < deadline) {
    tick_all(k++);
    bool all = true;
    for (auto& n : fleet) all = all && n->stats().births > 0;
    if (all) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }

  std::printf(
      "fleet bench: %d nodes x %d metrics, %.0f s per step, %s on 127.0.0.1:%d%s, %u CPUs\n", nodes,
      metrics, seconds, version.c_str(), port, nodelay ? " (set_tcp_nodelay true)" : "",
      std::thread::hardware_concurrency());
  std::printf("%10s %12s %12s %8s %9s %9s %9s %10s %8s\n", "rate/node", "offered/s", "delivered/s",
              "loss %", "p50 ms", "p99 ms", "max ms", "broker CPU", "stored");
  for (const double rate : rates) {
    {
      std::lock_guard lock(sink.mu);
      sink.latency_ms.clear();
      sink.received = 0;
      sink.gaps = 0;
    }
    std::uint64_t stored0 = 0;
    for (auto& n : fleet) stored0 += n->stats().stored;
    const double cpu0 = cpu_s(broker);
    const auto period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate));
    const auto t0 = Clock::now();
    auto next = t0;
    std::uint64_t offered = 0;
    while (Clock::now() - t0 < std::chrono::duration<double>(seconds)) {
      tick_all(k++);
      offered += static_cast<std::uint64_t>(nodes);
      next += period;
      std::this_thread::sleep_until(next);
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // in flight
    const double cpu = (cpu_s(broker) - cpu0) / elapsed * 100.0;
    std::uint64_t stored = 0;
    for (auto& n : fleet) stored += n->stats().stored;
    std::lock_guard lock(sink.mu);
    const double loss = offered == 0
                            ? 0.0
                            : 100.0 * (1.0 - static_cast<double>(std::min(sink.received, offered)) /
                                                 static_cast<double>(offered));
    std::printf("%10.0f %12.0f %12.0f %8.2f %9.2f %9.2f %9.2f %9.0f%% %8llu\n", rate,
                static_cast<double>(offered) / elapsed,
                static_cast<double>(sink.received) / elapsed, loss, pct(sink.latency_ms, 0.5),
                pct(sink.latency_ms, 0.99), pct(sink.latency_ms, 1.0), cpu,
                static_cast<unsigned long long>(stored - stored0));
    std::fflush(stdout);
  }
  for (auto& n : fleet) n->stop();
  mosquitto_disconnect(sub);
  mosquitto_loop_stop(sub, true);
  mosquitto_destroy(sub);
  kill(broker, SIGTERM);
  waitpid(broker, nullptr, 0);
  std::filesystem::remove_all(dir);
  return 0;
}
