#pragma once
// One browser's outgoing queue, bounded in bytes (docs/security.md "The browser HMI"). A browser
// that asks for the 2 MiB job and never reads must not make edmhmi hold copy after copy of it
// (issue 31: 8 such sockets took edmhmi from 19 MB to 698 MB). The bytes of every message queued
// — the one being written included — count against the socket's bound (kMaxQueuedBytes) and
// against one bound shared by every socket of the server (kMaxTotalQueuedBytes):
//   - a message always goes into an empty queue (one message is bounded by its source: a reply,
//     the welcome, ≤ ~4 MiB);
//   - a frame (telemetry, status) that does not fit is dropped and counted;
//   - a reply that does not fit means the browser asks and does not read: the socket is closed.
// A message shared by several sockets (a broadcast frame) counts in full in each.
//
// Non-RT. Thread-safety: none (the server's I/O thread; the shared total is that thread's too).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace edm::hmi {

inline constexpr std::size_t kMaxQueuedBytes = std::size_t{4} << 20;
inline constexpr std::size_t kMaxTotalQueuedBytes = std::size_t{64} << 20;
inline constexpr std::size_t kMaxQueuedMessages = 256;

class WebOutbox {
 public:
  enum class Kind : std::uint8_t { kFrame, kReply };
  enum class Push : std::uint8_t {
    kStartWrite,  // queued into an empty queue: start writing it
    kQueued,      // queued behind others
    kDropped,     // a frame that does not fit, dropped
    kOverflow,    // a reply that does not fit: close the socket
  };

  /// `total`: the bytes queued by every socket of the server (outlives the outbox).
  explicit WebOutbox(std::size_t& total, std::size_t max_bytes = kMaxQueuedBytes,
                     std::size_t max_total = kMaxTotalQueuedBytes)
      : total_(total), max_bytes_(max_bytes), max_total_(max_total) {}
  ~WebOutbox() { clear(); }
  WebOutbox(const WebOutbox&) = delete;
  WebOutbox& operator=(const WebOutbox&) = delete;

  Push push(std::shared_ptr<const std::string> message, Kind kind) {
    const std::size_t n = message->size();
    if (!queue_.empty()) {
      const bool fits = queue_.size() < kMaxQueuedMessages && bytes_ + n <= max_bytes_ &&
                        total_ + n <= max_total_;
      if (!fits) {
        if (kind == Kind::kReply) return Push::kOverflow;
        ++dropped_;
        return Push::kDropped;
      }
    } else if (total_ + n > max_total_ && kind == Kind::kFrame) {
      ++dropped_;
      return Push::kDropped;
    }
    bytes_ += n;
    total_ += n;
    queue_.push_back(std::move(message));
    return queue_.size() == 1 ? Push::kStartWrite : Push::kQueued;
  }
  /// The message being written (the queue is not empty).
  [[nodiscard]] const std::string& front() const { return *queue_.front(); }
  /// The front message is written; true when another waits.
  bool pop() {
    bytes_ -= queue_.front()->size();
    total_ -= queue_.front()->size();
    queue_.pop_front();
    return !queue_.empty();
  }
  void clear() {
    total_ -= bytes_;
    bytes_ = 0;
    queue_.clear();
  }
  [[nodiscard]] bool empty() const noexcept { return queue_.empty(); }
  [[nodiscard]] std::size_t bytes() const noexcept { return bytes_; }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }

 private:
  std::size_t& total_;
  std::size_t max_bytes_, max_total_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  std::size_t bytes_{0};
  std::uint64_t dropped_{0};
};

}  // namespace edm::hmi
