#pragma once
// Throttle of failed hellos (docs/security.md "Token guessing"), at two levels:
//  - per key: the transport address, or (transport address, hello's "peer") when a relaying HMI
//    (edmhmi serve) names the end client. After n failures of a key within kForgetAfter of each
//    other, no further hello of that key is *evaluated* before kBaseDelay·2^(n−1) (at most
//    kMaxDelay) has passed since its last failure (FailureBackoff, edmhmi's schedule too). So one
//    browser's failures behind edmhmi do not delay another browser's log-in.
//  - per transport address (aggregate, whatever the peer): at most kAggregateFailures failures
//    in any kForgetAfter window; a hello that would exceed it waits until the oldest of them has
//    left the window. A client that names a new peer in every hello still guesses at most
//    kAggregateFailures times a window; a single peer never reaches it (its own delay allows
//    about 13 failures a window).
// Hellos that arrive earlier wait — on any number of connections — so the guessing rate is
// bounded whether or not the guesser waits for the answers. A right token is never refused, only
// delayed; a success does not forget the failures (a viewer's token must not reset the throttle
// of someone guessing the operator's).
//
// Thread-safety: none (the bridge's io thread only). Not RT-safe (allocates).

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>

#include "edm/bridge/failure_backoff.hpp"

namespace edm::bridge {

class HelloThrottle {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr auto kBaseDelay = FailureBackoff::kBaseDelay;
  static constexpr auto kMaxDelay = FailureBackoff::kMaxDelay;
  static constexpr auto kForgetAfter = FailureBackoff::kForgetAfter;
  static constexpr std::size_t kAggregateFailures = 64;

  /// At most `max_keys` keys and as many addresses are remembered (the stalest go first).
  explicit HelloThrottle(std::size_t max_keys = 4096) : max_keys_(max_keys) {}

  /// When a hello from `address` naming `peer` ("" = none) may be evaluated (<= now: at once).
  [[nodiscard]] Clock::time_point admit_at(const std::string& address, std::string_view peer,
                                           Clock::time_point now);
  /// A hello from `address` naming `peer` failed at `now`; returns how long from now the next
  /// hello of that key waits (its own delay or the address's aggregate, the longer).
  std::chrono::milliseconds on_failure(const std::string& address, std::string_view peer,
                                       Clock::time_point now);

  [[nodiscard]] std::uint64_t failures() const noexcept { return failures_; }
  [[nodiscard]] std::size_t keys() const noexcept { return keys_.size(); }
  [[nodiscard]] std::size_t addresses() const noexcept { return addresses_.size(); }

 private:
  using Key = FailureBackoff;  // one key's schedule
  // The last kAggregateFailures failure times of one address, a ring (oldest at `next` when full).
  struct Address {
    std::array<Clock::time_point, kAggregateFailures> times{};
    std::size_t count{0};
    std::size_t next{0};
    [[nodiscard]] Clock::time_point newest() const noexcept {
      return times[(next + kAggregateFailures - 1) % kAggregateFailures];
    }
  };
  static std::string key_of(const std::string& address, std::string_view peer);
  [[nodiscard]] Clock::time_point aggregate_at(const std::string& address, Clock::time_point now);
  template <class Map>
  void forget_stalest(Map& map);

  std::size_t max_keys_;
  std::unordered_map<std::string, Key> keys_;
  std::unordered_map<std::string, Address> addresses_;
  std::uint64_t failures_{0};
};

}  // namespace edm::bridge
