#include "jitter_load.hpp"

#include <fmt/core.h>
#include <signal.h>

#include <chrono>
#include <regex>
#include <sstream>

namespace edm::bench {

using namespace std::chrono_literals;

std::optional<std::string> pinned_config(const std::string& text, std::optional<int> cpu,
                                         int sessions, std::string& error) {
  std::istringstream in(text);
  std::string out;
  int tasks = 0;
  bool bridge = false;
  // Block-style task entries, as the shipped bench configs write them.
  static const std::regex kPriority(R"(^(\s+)priority:\s*\d+\s*$)");
  static const std::regex kBridge(R"(^bridge:\s*\{port:\s*0\}\s*$)");
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_match(line, kBridge)) {
      line = fmt::format("bridge: {{port: 0, max_sessions: {}}}", sessions);
      bridge = true;
    }
    out += line + "\n";
    if (std::regex_match(line, m, kPriority)) {
      ++tasks;
      if (cpu) {
        out += fmt::format("{}cpu: {}\n", m[1].str(), *cpu);
      }
    }
  }
  if (tasks == 0 || !bridge) {
    error =
        tasks == 0 ? "no task with a `priority:` line of its own" : "no `bridge: {port: 0}` line";
    return std::nullopt;
  }
  return out;
}

StressLoad::StressLoad(const std::string& stress_ng, const std::string& cpus, int workers,
                       const std::string& log) {
  const std::vector<std::string> args{stress_ng,
                                      "--cpu",
                                      std::to_string(workers),
                                      "--vm",
                                      std::to_string(workers),
                                      "--vm-bytes",
                                      "256M",
                                      "--taskset",
                                      cpus,
                                      "--timeout",
                                      "0"};
  for (const std::string& a : args) {
    command_ += (command_.empty() ? "" : " ") + a;
  }
  edm::apps::SpawnOptions o;
  o.out = edm::apps::Stream::kFile;
  o.out_file = log;
  proc_ = edm::apps::Process(args, o);
}

std::string StressLoad::failure() {
  if (!proc_.started()) {
    return "stress-ng did not start: " + proc_.error();
  }
  if (proc_.poll()) {
    return "stress-ng ended: " + proc_.describe();
  }
  return {};
}

void StressLoad::stop() {
  if (proc_.started() && !proc_.ended()) {
    proc_.stop(SIGTERM, 5s);
  }
}

std::string BridgePollers::start(int port) {
  stop();
  stop_.store(false);
  replies_.store(0);
  edm::bridge::ClientOptions co;
  co.port = static_cast<std::uint16_t>(port);
  co.timeout = 2000ms;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  for (int i = 0; i < clients_; ++i) {
    auto c = std::make_unique<edm::bridge::Client>();
    for (;;) {
      try {
        c->connect(co);
        break;
      } catch (const edm::bridge::ClientError& e) {
        if (std::chrono::steady_clock::now() > deadline) {
          return fmt::format("bridge client {} could not connect to port {}: {}", i, port,
                             e.what());
        }
        std::this_thread::sleep_for(20ms);  // edmplc is starting: poll with a deadline
      }
    }
    sessions_.push_back(std::move(c));
  }
  const auto period = std::chrono::nanoseconds(1'000'000'000 / rate_hz_);
  for (auto& session : sessions_) {
    edm::bridge::Client* c = session.get();
    threads_.emplace_back([this, c, period] {
      auto next = std::chrono::steady_clock::now();
      while (!stop_.load()) {
        if (!c->request("status")) {
          return;  // edmplc has gone (its run is over)
        }
        replies_.fetch_add(1);
        next += period;
        std::this_thread::sleep_until(next);
      }
    });
  }
  return {};
}

void BridgePollers::stop() {
  stop_.store(true);
  for (std::thread& t : threads_) {
    t.join();
  }
  threads_.clear();
  for (auto& c : sessions_) {
    c->close();
  }
  sessions_.clear();
}

}  // namespace edm::bench
