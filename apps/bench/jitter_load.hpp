#pragma once
// The jitter bench's conditions (jitter_bench.cpp, docs/benchmarks.md): the config edmplc runs as
// a user would configure it (its tasks pinned through their own `cpu:` key), CPU + memory load
// with stress-ng on the other CPUs, and bridge clients polling `status`.
// Non-RT. Not thread-safe: from the driver's main thread (BridgePollers owns its threads).

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "edm/apps/subprocess.hpp"
#include "edm/bridge/client.hpp"

namespace edm::bench {

/// The text of a bench config with `cpu: N` added to every task (after its `priority:` line)
/// and room for `sessions` bridge sessions; nullopt with `error` set when the config has no
/// task in the expected block style or no `bridge: {port: 0}` line.
std::optional<std::string> pinned_config(const std::string& text, std::optional<int> cpu,
                                         int sessions, std::string& error);

/// stress-ng with one CPU worker and one memory worker (256 MiB) per CPU of `cpus` (taskset
/// list, e.g. "0"), until stopped. Its output goes to `log`.
class StressLoad {
 public:
  StressLoad(const std::string& stress_ng, const std::string& cpus, int workers,
             const std::string& log);
  ~StressLoad() { stop(); }
  StressLoad(const StressLoad&) = delete;
  StressLoad& operator=(const StressLoad&) = delete;
  /// Empty while it runs, else what went wrong.
  [[nodiscard]] std::string failure();
  /// The command line, for the report.
  [[nodiscard]] const std::string& command() const { return command_; }
  void stop();

 private:
  edm::apps::Process proc_;
  std::string command_;
};

/// `clients` bridge sessions on 127.0.0.1:port, each a thread sending `status` at `rate_hz` on an
/// absolute grid (an HMI polling), from start() until stop() or the first failed request.
class BridgePollers {
 public:
  BridgePollers(int clients, int rate_hz) : clients_(clients), rate_hz_(rate_hz) {}
  ~BridgePollers() { stop(); }
  BridgePollers(const BridgePollers&) = delete;
  BridgePollers& operator=(const BridgePollers&) = delete;

  /// Connects every client (retrying for up to 10 s while edmplc starts), then starts polling.
  /// Returns "" or why not.
  std::string start(int port);
  /// Stops polling and disconnects. Idempotent.
  void stop();
  /// Replies received since start().
  [[nodiscard]] std::uint64_t replies() const { return replies_.load(); }

 private:
  int clients_;
  int rate_hz_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> replies_{0};
  std::vector<std::thread> threads_;
  std::vector<std::unique_ptr<edm::bridge::Client>> sessions_;
};

}  // namespace edm::bench
