#pragma once
// A raw Modbus TCP client for the server's tests: a real socket from a chosen loopback source
// address (all of 127.0.0.0/8 is this host, so one test can be many peers), whole frames or any
// bytes, replies read with a deadline (poll), the server's close observed with a deadline.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace edm::test {

/// A Modbus TCP frame: MBAP (transaction, protocol 0, length, unit) and the PDU.
inline std::vector<std::uint8_t> mb_frame(const std::vector<std::uint8_t>& pdu,
                                          std::uint16_t tid = 1, std::uint8_t unit = 1) {
  const auto len = static_cast<std::uint16_t>(pdu.size() + 1);
  std::vector<std::uint8_t> f{
      static_cast<std::uint8_t>(tid >> 8), static_cast<std::uint8_t>(tid & 0xFF), 0,   0,
      static_cast<std::uint8_t>(len >> 8), static_cast<std::uint8_t>(len & 0xFF), unit};
  f.insert(f.end(), pdu.begin(), pdu.end());
  return f;
}

class RawClient {
 public:
  using Clock = std::chrono::steady_clock;

  /// Connects to 127.0.0.1:port from `from` (any port). rcvbuf > 0: SO_RCVBUF before connecting.
  explicit RawClient(int port, const std::string& from = "127.0.0.1", int rcvbuf = 0)
      : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    sockaddr_in src{};
    src.sin_family = AF_INET;
    ::inet_pton(AF_INET, from.c_str(), &src.sin_addr);
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (rcvbuf > 0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    }
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&src), sizeof src) == 0 &&
                 ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  }
  ~RawClient() { ::close(fd_); }
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;

  [[nodiscard]] bool connected() const { return connected_; }
  [[nodiscard]] int fd() const { return fd_; }

  bool send(const std::vector<std::uint8_t>& b) {
    return ::send(fd_, b.data(), b.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(b.size());
  }

  /// The next whole reply (as its MBAP length says) within `within`; empty when the server
  /// closed the connection or said nothing.
  std::vector<std::uint8_t> reply(std::chrono::milliseconds within = std::chrono::seconds(2)) {
    const auto end = Clock::now() + within;
    for (;;) {
      if (buf_.size() >= 6) {
        const std::size_t total = 6U + ((buf_[4] << 8) | buf_[5]);
        if (buf_.size() >= total) {
          std::vector<std::uint8_t> r(buf_.begin(), buf_.begin() + static_cast<long>(total));
          buf_.erase(buf_.begin(), buf_.begin() + static_cast<long>(total));
          return r;
        }
      }
      if (!fill(end)) {
        return {};
      }
    }
  }

  /// True when the server closes the connection (EOF or reset) within `within`; what it sends
  /// before is discarded.
  bool closed_within(std::chrono::milliseconds within) {
    const auto end = Clock::now() + within;
    while (fill(end)) {
      buf_.clear();
    }
    return closed_;
  }
  [[nodiscard]] bool closed() const { return closed_; }

 private:
  // Reads what is there by `end`; false on EOF, error or the deadline.
  bool fill(Clock::time_point end) {
    if (closed_) {
      return false;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now());
    if (left.count() < 0) {
      return false;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) {
      return false;
    }
    std::uint8_t b[4096];
    const ssize_t n = ::recv(fd_, b, sizeof b, 0);
    if (n <= 0) {
      closed_ = n == 0 || errno == ECONNRESET || errno == EPIPE;
      return false;
    }
    buf_.insert(buf_.end(), b, b + n);
    return true;
  }

  int fd_;
  bool connected_{false};
  bool closed_{false};
  std::vector<std::uint8_t> buf_;
};

}  // namespace edm::test
