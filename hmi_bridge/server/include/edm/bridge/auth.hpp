#pragma once
// Bridge authentication (DESIGN §9, docs/protocol.md "Authentication"): two token files, one per
// role. A token file must be a regular file readable by its owner only (no group/other bits):
// the server refuses to start otherwise, and refuses to bind a non-loopback address when no
// token is configured. Without tokens only loopback clients are served, as operator.
//
// Thread-safety: pure functions and an immutable value type (thread-safe). Not for RT threads.

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "edm/bridge/protocol.hpp"

namespace edm::bridge {

/// Why the server will not start (bad token file, unsafe bind, bind failure). what() is the
/// whole message, e.g. "bridge.token_file /etc/edm/op.token: readable by group/others (mode
/// 0644); chmod 600 it".
class BridgeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TokenSet {
  std::string operator_token;  // empty: none configured
  std::string viewer_token;
  [[nodiscard]] bool any() const noexcept {
    return !operator_token.empty() || !viewer_token.empty();
  }
};

/// Shortest and longest token accepted: 16 characters is 64 bits as hex, the least that the
/// failed-hello throttle makes impractical to guess.
inline constexpr std::size_t kMinTokenChars = 16;
inline constexpr std::size_t kMaxTokenChars = 1024;

/// Throws BridgeError unless `path` is a regular file with no group/other permission bits
/// (token files, the TLS key). `key` names the config key in messages.
void check_private_file(const std::string& path, std::string_view key);

/// Reads one token file: the first line without surrounding whitespace. Throws BridgeError when
/// the file is missing, not a regular file, readable or writable by group/others, empty, or
/// when the token is shorter than kMinTokenChars or longer than kMaxTokenChars.
/// `key` names the config key in messages.
std::string read_token_file(const std::string& path, std::string_view key);

/// Loads both files (empty path: that role has no token). Throws BridgeError as above, and when
/// both roles have the same token.
TokenSet load_tokens(const std::string& operator_file, const std::string& viewer_file);

/// Compares in time independent of where the strings differ (and of b's length).
bool constant_time_equal(std::string_view a, std::string_view b) noexcept;

/// The role a hello earns, or nullopt (unauthorized). Without any configured token every
/// loopback client is an operator and non-loopback clients are refused.
std::optional<Role> authenticate(const TokenSet& tokens, std::string_view token,
                                 bool client_is_loopback) noexcept;

/// True for 127.0.0.0/8, ::1 and v4-mapped loopback. False for anything unparsable.
bool is_loopback_address(const std::string& address) noexcept;

}  // namespace edm::bridge
