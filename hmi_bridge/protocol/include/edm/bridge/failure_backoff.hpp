#pragma once
// The schedule of failed log-ins that edmplc's hello throttle (bridge::HelloThrottle) and
// `edmhmi serve`'s log-in throttle (hmi::LoginThrottle) share, so that both ends of a relayed
// log-in delay a guesser alike (docs/security.md "Token guessing"): after n failures within
// kForgetAfter of each other, the next attempt is not evaluated before kBaseDelay·2^(n−1), at
// most kMaxDelay, has passed since the last failure.
//
// Non-RT. Thread-safety: a plain value (each throttle's I/O thread only). Time is passed in.

#include <algorithm>
#include <chrono>
#include <cstdint>

namespace edm::bridge {

struct FailureBackoff {
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kBaseDelay{250};
  static constexpr std::chrono::milliseconds kMaxDelay{10'000};
  static constexpr std::chrono::seconds kForgetAfter{60};

  std::uint32_t failures{0};
  Clock::time_point last_failure{};
  Clock::time_point admit_at{};  // the next attempt is evaluated from here on

  /// True when the last failure is older than kForgetAfter (the failures no longer count).
  [[nodiscard]] bool forgotten(Clock::time_point now) const noexcept {
    return now - last_failure > kForgetAfter;
  }
  /// Counts a failure at `now` (after forgetting old ones) and sets admit_at; the delay.
  std::chrono::milliseconds fail(Clock::time_point now) noexcept {
    if (failures > 0 && forgotten(now)) failures = 0;
    ++failures;
    last_failure = now;
    const int shift = static_cast<int>(std::min<std::uint32_t>(failures - 1, 16));
    const auto delay = std::min<std::chrono::milliseconds>(kBaseDelay * (1LL << shift), kMaxDelay);
    admit_at = now + delay;
    return delay;
  }
};

}  // namespace edm::bridge
