#include "edm/runtime/histogram.hpp"

#include <algorithm>
#include <cmath>

namespace edm::rt {

void LatencyHistogram::record(std::int64_t ns) noexcept {
  const std::uint64_t value = ns < 0 ? 0 : static_cast<std::uint64_t>(ns);
  // Single writer: a load + store is enough and avoids a locked RMW on the RT path.
  if (value > max_ns_.load(std::memory_order_relaxed)) {
    max_ns_.store(value, std::memory_order_relaxed);
  }
  std::atomic<std::uint64_t>& bin = bins_[bucket_index(value)];
  bin.store(bin.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  // Release: a reader that sees this count also sees the bin and max_ns_ written above.
  count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

std::int64_t LatencyHistogram::quantile(double q) const noexcept {
  const std::uint64_t total = count_.load(std::memory_order_acquire);
  if (total == 0) {
    return 0;
  }
  // Read after count_: at least as new as every value counted in total.
  const std::uint64_t max_value = max_ns_.load(std::memory_order_relaxed);
  const double clamped_q = std::isnan(q) ? 0.0 : std::clamp(q, 0.0, 1.0);
  // Rank = ceil(q * total), but 0.07 * 100 is 7.000000000000001: snap near-integers first.
  const double exact_rank = clamped_q * static_cast<double>(total);
  const double nearest = std::round(exact_rank);
  const double rounded_rank = std::abs(exact_rank - nearest) <= 1e-9 * std::max(1.0, exact_rank)
                                  ? nearest
                                  : std::ceil(exact_rank);
  const auto rank = std::clamp<std::uint64_t>(static_cast<std::uint64_t>(rounded_rank), 1, total);

  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBucketCount; ++i) {
    seen += bins_[i].load(std::memory_order_relaxed);
    if (seen >= rank) {
      // The last bucket also holds values above its nominal range: only max is known there.
      const std::uint64_t upper = i == kBucketCount - 1 ? max_value : bucket_upper_ns(i);
      return static_cast<std::int64_t>(std::min(upper, max_value));
    }
  }
  // Unreachable unless reset() races with readers (a documented misuse).
  return static_cast<std::int64_t>(max_value);
}

void LatencyHistogram::reset() noexcept {
  for (auto& bin : bins_) {
    bin.store(0, std::memory_order_relaxed);
  }
  max_ns_.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_release);
}

}  // namespace edm::rt
