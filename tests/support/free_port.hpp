#pragma once
// A free loopback TCP port for tests that start a server process (test code only).

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace edm::test {

/// Binds port 0 on 127.0.0.1, reads the port back and releases it; the caller's server binds it
/// right after (a small race with other processes, acceptable in tests).
inline int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

}  // namespace edm::test
