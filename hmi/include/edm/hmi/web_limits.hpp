#pragma once
// How many connections `edmhmi serve` holds at once (docs/security.md "The browser HMI"), so
// many sockets — a slowloris that trickles its headers, a flood of upgrades — cannot take every
// slot nor every descriptor: a cap in all and a cap per peer address, each connection holding
// its slot until it ends.
//
// Non-RT. Thread-safety: none (the server's single I/O thread).

#include <cstddef>
#include <memory>
#include <string>
#include <unordered_map>

namespace edm::hmi {

/// TCP connections (HTTP, and the WebSockets upgraded from them).
inline constexpr std::size_t kMaxWebConnections = 256;
inline constexpr std::size_t kMaxWebConnectionsPerAddress = 32;
/// WebSockets among them (each may hold an outgoing queue of kMaxQueuedBytes).
inline constexpr std::size_t kMaxWebSockets = 64;

class ConnectionCounter : public std::enable_shared_from_this<ConnectionCounter> {
 public:
  /// Held for as long as the connection lives; its destruction gives the slot back.
  using Slot = std::shared_ptr<void>;

  ConnectionCounter(std::size_t max_total, std::size_t max_per_address)
      : max_total_(max_total), max_per_address_(max_per_address) {}

  /// A slot for a connection from `address`; null when every slot, or every slot of that
  /// address, is taken.
  Slot acquire(const std::string& address) {
    std::size_t& n = per_address_[address];
    if (total_ >= max_total_ || n >= max_per_address_) {
      if (n == 0) per_address_.erase(address);
      return nullptr;
    }
    ++n;
    ++total_;
    return Slot(static_cast<void*>(this),
                [self = shared_from_this(), address](void*) { self->release(address); });
  }
  [[nodiscard]] std::size_t total() const noexcept { return total_; }

 private:
  void release(const std::string& address) {
    --total_;
    const auto it = per_address_.find(address);
    if (it != per_address_.end() && --it->second == 0) per_address_.erase(it);
  }

  std::size_t max_total_, max_per_address_;
  std::size_t total_{0};
  std::unordered_map<std::string, std::size_t> per_address_;
};

}  // namespace edm::hmi
