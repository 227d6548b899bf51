#pragma once
// LogRateLimiter: repeated log lines from one peer, rate-limited (issue 31). A token bucket per
// key (a peer's address): `burst` lines at once, then `per_s` a second; the lines beyond are
// counted, not logged, and the count is reported once — with the key's next logged line, or by
// sweep() once the key has been quiet — as one summary ("N lines suppressed"). So a client that
// sends a million bad requests costs the log a few lines a second, and the log still says that
// it happened and how often.
//
//   std::uint64_t dropped = 0;
//   if (limiter.admit(peer_address, now, dropped)) {
//     spdlog::warn("bridge: {} …{}", peer, rt::suppressed_note(dropped));
//   }
//
// Used by the bridge, the Modbus server and the MQTT publisher (runtime is their common base).
// Thread-safety: every member is thread-safe (one internal mutex). Not RT-safe (allocates).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>

namespace edm::rt {

class LogRateLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  struct Options {
    double burst{20.0};          // lines a quiet key may log at once
    double per_s{1.0};           // lines a second in the long run
    std::size_t max_keys{1024};  // keys remembered (the longest unused is forgotten first)
  };

  LogRateLimiter() : LogRateLimiter(Options{}) {}
  explicit LogRateLimiter(Options o) : opt_(o) {}

  /// A line from `key` at `now`: true to log it. False: suppressed (counted). When true and
  /// lines of this key were suppressed since its last logged one, `suppressed` says how many
  /// (and the count restarts); else it is 0.
  bool admit(std::string_view key, Clock::time_point now, std::uint64_t& suppressed);

  /// Calls fn(key, n) for every key with n > 0 suppressed lines whose last suppressed line is at
  /// least `quiet` old, and restarts its count. Call it now and then (a timer) so that a flood
  /// that stops is still summed up.
  void sweep(Clock::time_point now, std::chrono::milliseconds quiet,
             const std::function<void(const std::string& key, std::uint64_t n)>& fn);

  /// Lines suppressed since construction (all keys).
  [[nodiscard]] std::uint64_t suppressed_total() const;

 private:
  struct Bucket {
    double tokens{0.0};
    Clock::time_point refilled{};
    Clock::time_point last_suppressed{};
    std::uint64_t suppressed{0};
  };
  void forget_one();

  Options opt_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Bucket> buckets_;
  std::uint64_t total_{0};
};

/// " (N earlier lines suppressed)" for N > 0, "" for 0: appended to the next logged line.
[[nodiscard]] std::string suppressed_note(std::uint64_t n);

}  // namespace edm::rt
