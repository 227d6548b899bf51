#include "audit.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

#include "edm/bridge/auth.hpp"

namespace edm::bridge {

void AuditLog::open(const std::string& file) {
  if (file.empty()) {
    return;
  }
  const int fd = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw BridgeError("bridge.audit_file " + file + ": " + std::strerror(errno));
  }
  fd_ = fd;
}

AuditLog::~AuditLog() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

void AuditLog::record(std::uint64_t session, std::string_view role, std::string_view peer,
                      std::string_view op, std::string_view detail, std::string_view outcome) {
  spdlog::info("audit: session={} role={} peer={} op={}{}{} -> {}", session, role, peer, op,
               detail.empty() ? "" : " ", detail, outcome);
  if (fd_ < 0) {
    return;
  }
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
  const std::string line = fmt::format("{}.{:03d}Z session={} role={} peer={} op={}{}{} -> {}\n",
                                       stamp, static_cast<int>(ms), session, role, peer, op,
                                       detail.empty() ? "" : " ", detail, outcome);
  // One write() per entry with O_APPEND: entries never interleave, and a crash loses at most
  // the entry being written.
  if (::write(fd_, line.data(), line.size()) < 0) {
    spdlog::warn("bridge: audit file write failed: {}", std::strerror(errno));
  }
}

}  // namespace edm::bridge
