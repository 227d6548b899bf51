#pragma once
// Exponential back-off with an episode (docs/web.md): the accept loop of `edmhmi serve` at
// EMFILE/ENFILE (10 ms doubling to 1 s, as the bridge's) and its reconnection to edmplc (250 ms
// doubling to 5 s). The first failure of an episode says so (log once), success ends it.
//
// Pure value type; not thread-safe.

#include <algorithm>
#include <chrono>
#include <cstdint>

namespace edm::hmi {

class Backoff {
 public:
  constexpr Backoff(std::chrono::milliseconds first, std::chrono::milliseconds max)
      : first_(first), max_(max) {}

  /// A failure: the delay to wait before the next try. `*starts_episode` is true for the first
  /// failure since the last success (the one to log).
  std::chrono::milliseconds fail(bool* starts_episode = nullptr) {
    const bool first = delay_.count() == 0;
    delay_ = first ? first_ : std::min(delay_ * 2, max_);
    ++failures_;
    if (starts_episode != nullptr) *starts_episode = first;
    return delay_;
  }
  /// A success. Returns the failures of the episode it ends (0: there was none).
  std::uint64_t succeed() {
    const std::uint64_t n = failures_;
    delay_ = std::chrono::milliseconds(0);
    failures_ = 0;
    return n;
  }
  [[nodiscard]] bool in_episode() const noexcept { return delay_.count() != 0; }

 private:
  std::chrono::milliseconds first_, max_;
  std::chrono::milliseconds delay_{0};
  std::uint64_t failures_{0};
};

}  // namespace edm::hmi
