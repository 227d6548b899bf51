#pragma once
// TripleBuffer<T>: one writer hands whole values to one reader; neither ever waits, and the
// reader always gets the newest complete value (the "double-buffered image" of docs/modbus.md,
// with the third slot that makes it wait-free). The writer fills back(), then publish() swaps it
// with the shared middle slot; the reader's update() swaps the middle slot with its front() when
// a newer one is there. The slots are allocated once (construct, or resize through slots() before
// any thread uses it), so T may be a vector: nothing is allocated afterwards.
//
// RT-safety: back(), publish(), update() and front() are wait-free, no allocation or syscall.
// Thread-safety: back()/publish() from one writer thread, update()/front() from one reader.

#include <array>
#include <atomic>
#include <cstdint>

namespace edm::modbus {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  /// All three slots, for sizing before use. Non-RT; no thread may be using the buffer.
  std::array<T, 3>& slots() noexcept { return slots_; }

  /// The writer's slot. @note Writer only.
  T& back() noexcept { return slots_[back_]; }
  /// Makes back() the newest value; back() is then another slot. @note Writer only.
  void publish() noexcept {
    back_ = static_cast<std::uint8_t>(
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel) &
        kIndex);
  }
  /// Takes the newest published value into front() if there is one; true then. @note Reader.
  bool update() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) {
      return false;
    }
    front_ =
        static_cast<std::uint8_t>(middle_.exchange(front_, std::memory_order_acq_rel) & kIndex);
    return true;
  }
  /// The reader's current value. @note Reader only.
  const T& front() const noexcept { return slots_[front_]; }

 private:
  static constexpr std::uint8_t kIndex = 3;
  static constexpr std::uint8_t kFresh = 4;
  std::array<T, 3> slots_{};
  std::uint8_t back_{0};
  std::atomic<std::uint8_t> middle_{1};
  std::uint8_t front_{2};
};

}  // namespace edm::modbus
