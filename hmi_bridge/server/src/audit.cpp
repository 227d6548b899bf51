#include "audit.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

#include "edm/bridge/auth.hpp"
#include "edm/runtime/log_escape.hpp"

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

std::string AuditLog::format(const AuditEntry& e) {
  std::string line = fmt::format("session={} role={} peer={}", e.session, e.role, e.peer);
  if (!e.via.empty()) {
    line += " via=";
    rt::append_log_quoted(line, e.via);
  }
  line += " op=";
  // Only known op names are audited; escaped all the same, so no input can end the line.
  line += rt::is_printable_ascii(e.op) && e.op.find(' ') == std::string_view::npos
              ? std::string(e.op.substr(0, rt::kLogQuoteMaxBytes))
              : rt::log_quote(e.op);
  if (!e.detail.empty()) {
    line += ' ';
    line += e.detail;
  }
  line += " -> ";
  line += e.outcome;
  return line;
}

void AuditLog::record(const AuditEntry& e, rt::LogRateLimiter& limiter) {
  const std::string text = format(e);
  std::uint64_t suppressed = 0;
  if (limiter.admit(e.address, std::chrono::steady_clock::now(), suppressed)) {
    spdlog::info("audit: {}{}", text, rt::suppressed_note(suppressed));
  }
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
  const std::string line = fmt::format("{}.{:03d}Z {}\n", stamp, static_cast<int>(ms), text);
  // One write() per entry with O_APPEND: entries never interleave, and a crash loses at most
  // the entry being written.
  const bool failed = ::write(fd_, line.data(), line.size()) != static_cast<ssize_t>(line.size());
  if (failed && !write_failed_) {  // once per episode: a full disk must not flood the log too
    spdlog::warn("bridge: audit file write failed: {}", std::strerror(errno));
  } else if (!failed && write_failed_) {
    spdlog::info("bridge: audit file writable again");
  }
  write_failed_ = failed;
}

}  // namespace edm::bridge
