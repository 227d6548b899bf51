#pragma once
// Hostile bridge clients for edm-bench-soak: each is a seeded random state machine on a raw POSIX
// socket (so it can misbehave: no hello, wrong tokens, garbage, deep nesting, >1 MiB lines,
// pipelined requests never read, half lines, stalls, RST). They never send a state-changing op
// (estop, cycle.*, reset, var.write/force, program.*): they must not disturb the job.
// Non-RT. Thread-safety: one thread per client; the shared ActionLog is mutex-protected.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace edm::bench::soak {

using Clock = std::chrono::steady_clock;

/// What every client did, with its time since the soak began: written through to a file (so a
/// crash of edmplc can be traced to the actions just before it) and kept in memory for the tail.
class ActionLog {
 public:
  ActionLog(const std::string& path, Clock::time_point t0);
  ~ActionLog();
  ActionLog(const ActionLog&) = delete;
  ActionLog& operator=(const ActionLog&) = delete;

  void add(int client, const std::string& what);
  /// The entries logged in [t_from_s, t_to_s] (seconds since t0), oldest first.
  [[nodiscard]] std::vector<std::string> between(double t_from_s, double t_to_s) const;
  /// How many times each action kind (the first word) was logged.
  [[nodiscard]] std::map<std::string, std::uint64_t> counts() const;
  [[nodiscard]] double now_s() const;

 private:
  struct Entry {
    double t_s;
    std::string line;
  };
  mutable std::mutex mutex_;
  std::FILE* file_{nullptr};
  Clock::time_point t0_;
  std::vector<Entry> recent_;  // ring of the last kRecent entries
  std::size_t next_{0};
  std::map<std::string, std::uint64_t> counts_;
  static constexpr std::size_t kRecent = 20000;
};

struct HostileOptions {
  int index{0};
  std::uint64_t seed{0};
  std::uint16_t port{0};
  std::vector<std::string> pins;  // trace.start candidates (from var.list)
  std::vector<std::string> vars;  // var.read candidates
  std::chrono::seconds max_stall{60};
  /// Action kinds this client never does (see kind_of() in soak_hostile.cpp; plus no_hello and
  /// wrong_token for the connect step): to find which behaviour breaks edmplc.
  std::set<std::string, std::less<>> skip;
};

/// Runs the client's random walk until `stop` is set (returns within ~1 s of it).
void run_hostile(const HostileOptions& o, ActionLog& log, const std::atomic<bool>& stop);

}  // namespace edm::bench::soak
