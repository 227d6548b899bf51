#pragma once
// The bridge's audit trail (DESIGN §9, docs/security.md): every state-changing request — and
// every refused one — with session, role, peer, op, a short detail and the outcome. Always to
// the log ("audit: …"); also appended to `bridge.audit_file` when one is configured.
//
// Thread-safety: none (the bridge's io thread only). Not RT-safe (allocates, writes a file).

#include <cstdint>
#include <string>
#include <string_view>

#include "edm/runtime/log_limiter.hpp"

namespace edm::bridge {

/// One audit entry. `via`, `op` and `detail` may hold client text: record() escapes op and via;
/// `detail` must already be built from escaped parts (rt::log_quote), as ops.cpp's is.
struct AuditEntry {
  std::uint64_t session{0};
  std::string_view role;
  std::string_view peer;     // address:port (the server's, not the client's)
  std::string_view address;  // the transport address, the log rate limit's key
  std::string_view via;      // hello's relayed end client, "" when none
  std::string_view op;
  std::string_view detail;
  std::string_view outcome;  // "ok" or the error code's name
};

class AuditLog {
 public:
  AuditLog() = default;
  /// Opens `file` for appending (created 0600; never through a symlink). Throws BridgeError.
  void open(const std::string& file);
  ~AuditLog();
  AuditLog(const AuditLog&) = delete;
  AuditLog& operator=(const AuditLog&) = delete;

  /// The entry's text, one line without a newline: "session=4 role=operator peer=… op=…".
  [[nodiscard]] static std::string format(const AuditEntry& e);
  /// Writes one entry to the file (every entry) and to the log (through `limiter`, keyed by the
  /// entry's address: a flood of refused requests does not flood the log; the file keeps all).
  void record(const AuditEntry& e, rt::LogRateLimiter& limiter);

 private:
  int fd_{-1};
  bool write_failed_{false};
};

}  // namespace edm::bridge
