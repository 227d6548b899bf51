#pragma once
// MpmcQueue<T, N>: the one bounded multi-producer queue of the runtime, for the RT log records
// (log.hpp) and the machine's alarms (machine.hpp). A ring of N cells with a sequence number per
// cell (D. Vyukov's bounded MPMC design).
//
// Not boost::lockfree::queue: its array freelist reads a node's link non-atomically while another
// thread may rewrite it (boostorg/lockfree#78), which ThreadSanitizer (./edm tsan) reports. Here
// every element is published by a release store of its cell's sequence, so TSan is clean.
// Producers never wait: a cell that is not free yet means "full" and push() returns false.
//
// RT-safety: push() and pop() are lock-free, noexcept, never allocate and never block.
// Thread-safety: any number of producer and consumer threads. Holds N elements inline
// (N × (sizeof(T) + 8) bytes plus two cache lines); construct it before the threads start.

#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

namespace edm::rt {

template <class T, std::size_t N>
class MpmcQueue {
  static_assert(N >= 2 && (N & (N - 1)) == 0, "N must be a power of two");
  static_assert(std::is_trivially_copyable_v<T>, "elements are copied in and out of the cells");

 public:
  static constexpr std::size_t kCapacity = N;

  MpmcQueue() noexcept {
    for (std::size_t i = 0; i < N; ++i) {
      cells_[i].seq.store(i, std::memory_order_relaxed);
    }
  }
  MpmcQueue(const MpmcQueue&) = delete;
  MpmcQueue& operator=(const MpmcQueue&) = delete;

  /// Enqueues a copy of v; false when full (or the consumer is still copying that cell out).
  bool push(const T& v) noexcept {
    std::size_t pos = enqueue_pos_.load(std::memory_order_relaxed);
    for (;;) {
      Cell& cell = cells_[pos & kMask];
      const std::ptrdiff_t d = diff(cell.seq.load(std::memory_order_acquire), pos);
      if (d == 0) {
        if (enqueue_pos_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
          cell.value = v;
          cell.seq.store(pos + 1, std::memory_order_release);
          return true;
        }
      } else if (d < 0) {
        return false;
      } else {
        pos = enqueue_pos_.load(std::memory_order_relaxed);  // another producer took pos
      }
    }
  }

  /// Dequeues the oldest element into out; false when empty, or when the next element is still
  /// being written by a producer (it shows up on a later call).
  bool pop(T& out) noexcept {
    std::size_t pos = dequeue_pos_.load(std::memory_order_relaxed);
    for (;;) {
      Cell& cell = cells_[pos & kMask];
      const std::ptrdiff_t d = diff(cell.seq.load(std::memory_order_acquire), pos + 1);
      if (d == 0) {
        if (dequeue_pos_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
          out = cell.value;
          cell.seq.store(pos + N, std::memory_order_release);
          return true;
        }
      } else if (d < 0) {
        return false;
      } else {
        pos = dequeue_pos_.load(std::memory_order_relaxed);
      }
    }
  }

 private:
  static constexpr std::size_t kMask = N - 1;

  struct Cell {
    std::atomic<std::size_t> seq;  // == pos: free for push #pos; == pos + 1: holds push #pos
    T value{};
  };

  static std::ptrdiff_t diff(std::size_t a, std::size_t b) noexcept {
    return static_cast<std::ptrdiff_t>(a - b);  // wrap-around safe distance
  }

  std::array<Cell, N> cells_;
  alignas(64) std::atomic<std::size_t> enqueue_pos_{0};  // own cache lines: producers vs consumers
  alignas(64) std::atomic<std::size_t> dequeue_pos_{0};
};

}  // namespace edm::rt
