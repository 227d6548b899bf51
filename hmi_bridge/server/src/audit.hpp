#pragma once
// The bridge's audit trail (DESIGN §9, docs/security.md): every state-changing request — and
// every refused one — with session, role, peer, op, a short detail and the outcome. Always to
// the log ("audit: …"); also appended to `bridge.audit_file` when one is configured.
//
// Thread-safety: none (the bridge's io thread only). Not RT-safe (allocates, writes a file).

#include <cstdint>
#include <string>
#include <string_view>

namespace edm::bridge {

class AuditLog {
 public:
  AuditLog() = default;
  /// Opens `file` for appending (created 0600; never through a symlink). Throws BridgeError.
  void open(const std::string& file);
  ~AuditLog();
  AuditLog(const AuditLog&) = delete;
  AuditLog& operator=(const AuditLog&) = delete;

  /// One entry. `outcome` is "ok" or the error code's name.
  void record(std::uint64_t session, std::string_view role, std::string_view peer,
              std::string_view op, std::string_view detail, std::string_view outcome);

 private:
  int fd_{-1};
};

}  // namespace edm::bridge
