#pragma once
// A fixed-size log-linear (HDR-style) histogram of non-negative nanosecond values.
//
// Buckets: values 0..127 ns each have their own bucket (exact); above that, every power of two
// [2^k, 2^(k+1)) is split into 64 equal sub-buckets, so a bucket is at most 1/64 (~1.6 %) of its
// lower bound wide. Values up to kMaxTrackedNs (2^41 - 1 ns, ~36 min) are bucketed; larger ones
// land in the last bucket, and max_ns() still records the true value.
//
// Thread safety: one writer (record(), the task's RT thread) and any number of concurrent readers
// (quantile(), count(), max_ns()). reset() only while nobody records.
// RT safety: record() is RT-safe (noexcept, O(1), no allocation, no locks, no RMW). The object
// never allocates (std::array storage, ~18 KiB); readers are O(kBucketCount) and not meant for RT.

#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace edm::rt {

class LatencyHistogram {
 public:
  /// log2 of the sub-buckets per power of two: 64 sub-buckets, relative width <= 1/64.
  static constexpr int kSubBucketBits = 6;
  static constexpr std::uint64_t kSubBucketCount = std::uint64_t{1} << kSubBucketBits;
  /// Values whose highest set bit is at most this are bucketed precisely (2^41 - 1 ns ~ 36 min).
  static constexpr int kMaxMsb = 40;
  static constexpr std::uint64_t kMaxTrackedNs = (std::uint64_t{1} << (kMaxMsb + 1)) - 1;
  /// Bucket index = shift * 64 + (v >> shift), with shift = max(0, bit_width(v) - 7).
  static constexpr std::size_t kBucketCount =
      static_cast<std::size_t>((kMaxMsb - kSubBucketBits) * kSubBucketCount + 2 * kSubBucketCount);

  /// Index of the bucket that holds `ns` (values above kMaxTrackedNs map to the last bucket).
  static constexpr std::size_t bucket_index(std::uint64_t ns) noexcept {
    if (ns > kMaxTrackedNs) {
      return kBucketCount - 1;
    }
    const auto width = static_cast<int>(std::bit_width(ns));  // libstdc++ 12 returns uint64_t
    const int shift = width > kSubBucketBits + 1 ? width - (kSubBucketBits + 1) : 0;
    return static_cast<std::size_t>(static_cast<std::uint64_t>(shift) * kSubBucketCount +
                                    (ns >> shift));
  }
  /// Smallest value (ns) that maps to bucket `index`.
  static constexpr std::uint64_t bucket_lower_ns(std::size_t index) noexcept {
    if (index < 2 * kSubBucketCount) {
      return index;
    }
    const std::uint64_t shift = index / kSubBucketCount - 1;
    return (index - shift * kSubBucketCount) << shift;
  }
  /// Largest value (ns) that maps to bucket `index` (for the last bucket: kMaxTrackedNs, although
  /// larger values are also counted there).
  static constexpr std::uint64_t bucket_upper_ns(std::size_t index) noexcept {
    if (index < 2 * kSubBucketCount) {
      return index;
    }
    const std::uint64_t shift = index / kSubBucketCount - 1;
    return bucket_lower_ns(index) + (std::uint64_t{1} << shift) - 1;
  }

  /// Adds one value; negative values count as 0.
  /// @note RT-safe: noexcept, O(1), no allocation, no locks. Single writer only.
  void record(std::int64_t ns) noexcept;

  /// Value (ns) at quantile q (clamped to 0..1): the upper bound of the bucket holding the
  /// ceil(q * count)-th smallest value, so the answer is conservative (never below the true
  /// quantile of the recorded values, at most 1/64 above it) and exact below 128 ns. It is capped
  /// at max_ns(), which also answers for values beyond kMaxTrackedNs. 0 when empty.
  /// @note Any thread, concurrently with record(); not RT (scans all buckets).
  [[nodiscard]] std::int64_t quantile(double q) const noexcept;

  /// Number of recorded values. @note Any thread.
  [[nodiscard]] std::uint64_t count() const noexcept {
    return count_.load(std::memory_order_acquire);
  }
  /// Largest recorded value (ns), exact even beyond kMaxTrackedNs; 0 when empty. @note Any thread.
  [[nodiscard]] std::int64_t max_ns() const noexcept {
    return static_cast<std::int64_t>(max_ns_.load(std::memory_order_relaxed));
  }

  /// Forgets every value. @note Not thread-safe: only while no thread records or reads.
  void reset() noexcept;

 private:
  std::array<std::atomic<std::uint64_t>, kBucketCount> bins_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> max_ns_{0};
};

static_assert(LatencyHistogram::kBucketCount == 2304, "128 exact + 64 per power of two, 2^7..2^40");
static_assert(LatencyHistogram::bucket_upper_ns(LatencyHistogram::kBucketCount - 1) ==
                  LatencyHistogram::kMaxTrackedNs,
              "the last bucket ends at kMaxTrackedNs");
static_assert(LatencyHistogram::kMaxTrackedNs >= (std::uint64_t{1} << 40),
              "must cover at least 2^40 ns (~18 min)");
static_assert(LatencyHistogram::bucket_index(LatencyHistogram::kMaxTrackedNs) ==
                  LatencyHistogram::kBucketCount - 1,
              "the largest tracked value maps to the last bucket");
static_assert(std::atomic<std::uint64_t>::is_always_lock_free,
              "record() must not fall back to a lock");

}  // namespace edm::rt
