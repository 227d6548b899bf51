#pragma once
// A free loopback TCP port, for the tests and bench drivers that start a server process.

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace edm::apps {

/// Binds port 0 on 127.0.0.1, reads the port back and releases it; the caller's server binds it
/// right after (a small race with other processes, acceptable in tests and benchmarks). 0 when no
/// socket could be bound (descriptors exhausted).
inline int free_port() noexcept {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
    port = ntohs(a.sin_port);
  }
  ::close(fd);
  return port;
}

}  // namespace edm::apps
