#pragma once
// Throttle of failed hellos per peer address (docs/security.md). After n failures from an
// address within kForgetAfter of each other, no further hello from it is *evaluated* before
// kBaseDelay·2^(n−1) (at most kMaxDelay) has passed since the last failure. Hellos that arrive
// earlier wait — on any number of connections — so the guessing rate of one address is bounded
// by the delay, whether or not the guesser waits for the answers. A right token is never
// refused, only delayed behind the throttle of its own address.
//
// Thread-safety: none (the bridge's io thread only). Not RT-safe (allocates).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>

namespace edm::bridge {

class HelloThrottle {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kBaseDelay{250};
  static constexpr std::chrono::milliseconds kMaxDelay{10'000};
  static constexpr std::chrono::seconds kForgetAfter{60};

  /// At most `max_peers` addresses are remembered (the stalest is forgotten first).
  explicit HelloThrottle(std::size_t max_peers = 4096) : max_peers_(max_peers) {}

  /// When a hello from `address` may be evaluated (<= now: at once).
  [[nodiscard]] Clock::time_point admit_at(const std::string& address, Clock::time_point now);
  /// A hello from `address` failed at `now`; returns the delay now in force for that address.
  std::chrono::milliseconds on_failure(const std::string& address, Clock::time_point now);
  /// A hello from `address` succeeded: its record is forgotten.
  void on_success(const std::string& address);

  [[nodiscard]] std::uint64_t failures() const noexcept { return failures_; }
  [[nodiscard]] std::size_t peers() const noexcept { return peers_.size(); }

 private:
  struct Peer {
    std::uint32_t failures{0};
    Clock::time_point last_failure{};
    Clock::time_point admit_at{};
  };
  void forget_stalest();

  std::size_t max_peers_;
  std::unordered_map<std::string, Peer> peers_;
  std::uint64_t failures_{0};
};

}  // namespace edm::bridge
