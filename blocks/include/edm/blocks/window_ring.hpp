#pragma once
// WindowRing<T>: the ring of the last N samples that the window blocks keep (MovingAverage,
// TdDetector, GreyPredictorGM11, ShortRetract's path history). N comes from a load-time parameter,
// so the slots are allocated once in configure() and never again; a push overwrites the oldest
// sample and hands it back, so a block can keep a running sum without rescanning the window.
//
// RT-safety: allocate() is not RT (allocates). Everything else is RT-safe: noexcept, O(1) (clear()
// is O(N)), no allocation. Thread-safety: none (a block's own state, used by its task only).

#include <algorithm>
#include <cstddef>
#include <vector>

namespace edm::blocks {

template <class T>
class WindowRing {
 public:
  /// Non-RT. capacity slots, all T{}; empty. Capacity 0 means "not configured".
  void allocate(std::size_t capacity) {
    slots_.assign(capacity, T{});
    next_ = 0;
    size_ = 0;
  }

  /// Empties the ring and sets every slot back to T{}. @note RT-safe.
  void clear() noexcept {
    std::fill(slots_.begin(), slots_.end(), T{});
    next_ = 0;
    size_ = 0;
  }

  /// Empties the ring in O(1) without touching the slots: push() then hands back stale samples,
  /// so only for a block that does not use push()'s return value. @note RT-safe.
  void forget() noexcept {
    next_ = 0;
    size_ = 0;
  }

  /// Removes the newest sample. @pre size() > 0. @note RT-safe.
  void pop_newest() noexcept {
    next_ = next_ == 0 ? slots_.size() - 1 : next_ - 1;
    --size_;
  }

  /// Appends x and returns what its slot held: the sample that left the window once the ring is
  /// full, T{} before. @pre capacity() > 0. @note RT-safe.
  T push(const T& x) noexcept {
    T& slot = slots_[next_];
    const T old = slot;
    slot = x;
    if (++next_ == slots_.size()) {
      next_ = 0;
    }
    if (size_ < slots_.size()) {
      ++size_;
    }
    return old;
  }

  /// The i-th oldest sample, 0 ≤ i < size(). @note RT-safe.
  [[nodiscard]] const T& operator[](std::size_t i) const noexcept {
    const std::size_t j = next_ + (slots_.size() - size_) + i;  // start of the window, then i
    return slots_[j < slots_.size() ? j : j - slots_.size()];
  }

  /// True when the next push writes the first slot: the ring holds exactly the samples pushed
  /// since it last started over (a block may restart a running sum from them). @note RT-safe.
  [[nodiscard]] bool at_first_slot() const noexcept { return next_ == 0; }

  [[nodiscard]] std::size_t capacity() const noexcept { return slots_.size(); }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool full() const noexcept { return size_ == slots_.size(); }

 private:
  std::vector<T> slots_;  // sized once by allocate()
  std::size_t next_{0};   // slot the next push overwrites
  std::size_t size_{0};   // samples in the window, ≤ capacity()
};

}  // namespace edm::blocks
