#pragma once
// RetractBudget: how many short retracts a cycle may make before alarm 150. A retract that
// follows progress (the retract child's tries back at 1: the hole or orbit advanced
// retract.progress_mm since the last one) starts the count again; more than `max` retracts
// without progress within `window` means a contact the retracts cannot clear.
// RT-safe (fixed storage, no allocation). Not thread-safe: the owning task.

#include <array>
#include <cstddef>
#include <cstdint>

#include "edm/runtime/time.hpp"

namespace edm::programs {

class RetractBudget {
 public:
  static constexpr std::int64_t kMaxRetracts = 16;

  /// A retract began at `now`; `tries` is the retract child's count since the last progress.
  /// True when this is one more than `max` (≤ kMaxRetracts) within `window`.
  bool exceeded(rt::TimePoint now, std::int64_t tries, std::int64_t max,
                rt::Duration window) noexcept {
    if (tries <= 1) {
      n_ = 0;
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < n_; ++k) {
      if (now - starts_[k] <= window) {
        starts_[kept++] = starts_[k];
      }
    }
    if (kept == starts_.size()) {  // full: forget the oldest (the count stays past any max)
      for (std::size_t k = 1; k < kept; ++k) {
        starts_[k - 1] = starts_[k];
      }
      --kept;
    }
    starts_[kept++] = now;
    n_ = kept;
    return static_cast<std::int64_t>(kept) > max;
  }
  [[nodiscard]] std::size_t count() const noexcept { return n_; }
  void reset() noexcept { n_ = 0; }

 private:
  std::array<rt::TimePoint, kMaxRetracts + 1> starts_{};
  std::size_t n_{0};
};

}  // namespace edm::programs
