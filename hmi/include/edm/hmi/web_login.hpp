#pragma once
// The log-in throttle of `edmhmi serve` (docs/security.md "The browser HMI"), per browser address.
// edmplc throttles failed hellos per peer address, and every browser's log-in reaches it from
// edmhmi's one address: without a throttle here, one page's wrong tokens would lock every other
// page out (issue 31: 40 wrong tokens in a second kept the right one out for minutes). So the
// browsers are throttled here, each by its own address, with edmplc's schedule (FailureBackoff,
// the one both use): after n failed log-ins from an address within kForgetAfter of each other,
// its next log-in is not checked before kBaseDelay·2^(n−1) (at most kMaxDelay) has passed since
// the last failure, and one log-in per address is checked at a time — the rest wait, on any number
// of sockets, so an address guesses at most once per delay however many sockets it opens. A right
// token is delayed, never refused, and does not forget the failures. The browser's address also
// goes to edmplc in the hello ("peer"), whose own throttle keys on it the same way.
//
// Non-RT. Thread-safety: none (the server's I/O thread only). Time is passed in (tests).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>

#include "edm/bridge/failure_backoff.hpp"

namespace edm::hmi {

class LoginThrottle {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr auto kBaseDelay = bridge::FailureBackoff::kBaseDelay;
  static constexpr auto kMaxDelay = bridge::FailureBackoff::kMaxDelay;
  static constexpr auto kForgetAfter = bridge::FailureBackoff::kForgetAfter;
  static constexpr std::size_t kMaxAddresses = 4096;

  explicit LoginThrottle(std::size_t max_addresses = kMaxAddresses)
      : max_addresses_(max_addresses) {}

  /// When a log-in from `address` may be checked (<= now: at once); nullopt while another log-in
  /// of that address is being checked (ask again when it ends).
  [[nodiscard]] std::optional<Clock::time_point> admit_at(const std::string& address,
                                                          Clock::time_point now);
  /// A log-in from `address` is being checked from now on.
  void begin(const std::string& address);
  /// It was refused (a wrong token) at `now`; returns the delay now in force for the address.
  std::chrono::milliseconds on_failure(const std::string& address, Clock::time_point now);
  /// It was accepted. Its failures stay until kForgetAfter (as edmplc's throttle keeps them).
  void on_success(const std::string& address);
  /// It could not be checked (edmplc unreachable): nothing is learnt about the token.
  void on_abandon(const std::string& address);

  [[nodiscard]] std::uint64_t failures() const noexcept { return failures_; }
  [[nodiscard]] std::size_t addresses() const noexcept { return peers_.size(); }

 private:
  struct Peer : bridge::FailureBackoff {
    bool checking{false};
  };
  Peer& peer(const std::string& address);
  void forget_stalest();

  std::size_t max_addresses_;
  std::unordered_map<std::string, Peer> peers_;
  std::uint64_t failures_{0};
};

}  // namespace edm::hmi
