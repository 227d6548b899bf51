#pragma once
// Seqlock<T>: one writer publishes a trivially copyable T; any number of readers take consistent
// copies without ever making the writer wait (the RT → non-RT snapshots of DESIGN §9).
//
// Memory orderings (the one set used for every seqlock here):
//   writer  version := odd (relaxed); each data word: store(release); version := even (release)
//   reader  v1 := version (acquire), retry if odd; each data word: load(acquire);
//           valid iff version (relaxed) == v1
// A reader that reads any word of write section k synchronises with that release store, which
// is sequenced after section k's odd version store, so its last version load (ordered after the
// acquire data loads) sees that odd value or later and the copy is discarded. A reader that
// validates saw v1 through an acquire of the writer's closing release, so it sees that section's
// words or newer ones, and newer ones would have moved the version. Acquire/release on every
// word rather than relaxed words between std::atomic_thread_fence: equally correct, free on x86,
// and GCC rejects fences under -fsanitize=thread (-Wtsan, an error with EDM_WERROR) while TSan
// models acquire/release exactly. Every shared byte lives in a std::atomic word: no data race.
//
// RT-safety: store() is RT-safe (noexcept, O(sizeof T), no allocation, lock or syscall, never
// waits for readers). try_load() is lock-free; load() retries and yields the CPU after a few
// attempts, so it is for non-RT threads only.
// Thread-safety: store() from one thread at a time; try_load()/load() from any thread; reset()
// only while nobody stores or loads.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <thread>
#include <type_traits>

namespace edm::rt {

template <class T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "Seqlock<T> copies T word by word");

 public:
  Seqlock() noexcept : Seqlock(T{}) {}
  explicit Seqlock(const T& initial) noexcept { write_words(initial, std::memory_order_relaxed); }
  Seqlock(const Seqlock&) = delete;
  Seqlock& operator=(const Seqlock&) = delete;

  /// Publishes a new value. @note RT-safe; single writer.
  void store(const T& value) noexcept {
    const std::uint64_t v = version_.load(std::memory_order_relaxed);  // writer's own value
    version_.store(v + 1, std::memory_order_relaxed);
    write_words(value, std::memory_order_release);
    version_.store(v + 2, std::memory_order_release);
  }

  /// One attempt: false (out untouched) while a store overlaps. @note Any thread; lock-free.
  [[nodiscard]] bool try_load(T& out) const noexcept {
    const std::uint64_t before = version_.load(std::memory_order_acquire);
    if ((before & 1U) != 0) {
      return false;
    }
    std::array<std::uint64_t, kWords> w;
    for (std::size_t i = 0; i < kWords; ++i) {
      w[i] = words_[i].load(std::memory_order_acquire);
    }
    if (version_.load(std::memory_order_relaxed) != before) {
      return false;
    }
    std::memcpy(static_cast<void*>(&out), w.data(), sizeof(T));  // T is trivially copyable
    return true;
  }

  /// A consistent copy; retries while the writer writes. @note Any thread; not RT.
  [[nodiscard]] T load() const noexcept {
    T out{};
    for (unsigned attempt = 0; !try_load(out); ++attempt) {
      if (attempt >= kSpinsBeforeYield) {
        std::this_thread::yield();  // the writer was preempted inside its short write section
      }
    }
    return out;
  }

  /// Replaces the value and advances the version, so that a copy begun before cannot validate.
  /// @note Only while nobody stores or loads.
  void reset(const T& value) noexcept {
    write_words(value, std::memory_order_relaxed);
    version_.store((version_.load(std::memory_order_relaxed) | 1U) + 1, std::memory_order_release);
  }

  /// Even, and advanced by 2 by each store(). @note Any thread.
  [[nodiscard]] std::uint64_t version() const noexcept {
    return version_.load(std::memory_order_acquire);
  }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  static constexpr unsigned kSpinsBeforeYield = 64;

  void write_words(const T& value, std::memory_order order) noexcept {
    std::array<std::uint64_t, kWords> w{};
    std::memcpy(w.data(), &value, sizeof(T));
    for (std::size_t i = 0; i < kWords; ++i) {
      words_[i].store(w[i], order);
    }
  }

  std::atomic<std::uint64_t> version_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace edm::rt
