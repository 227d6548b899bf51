#pragma once
// Where edmhmi finds edmplc and how it proves who it is (docs/hmi.md "Connecting"):
//   host   --host H        else $EDM_HOST        else 127.0.0.1
//   port   --port P        else $EDM_PORT        else 7730
//   token  --token-file F  else $EDM_TOKEN_FILE  else $EDM_TOKEN (the token itself) else none
//   TLS    --tls-ca F (verify the chain and host name) else $EDM_TLS_CA, or
//          --tls-fingerprint FP (pin the certificate's SHA-256) else $EDM_TLS_FINGERPRINT;
//          either one turns TLS on, else plain TCP
// A token file holds the token on its first line (surrounding white space is ignored). Without a
// token only a loopback edmplc without configured tokens answers (as operator).
//
// Non-RT; thread-compatible plain data and pure functions.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "edm/bridge/client.hpp"

namespace edm::hmi {

struct ConnectionSettings {
  std::string host{"127.0.0.1"};
  std::uint16_t port{7730};
  std::string token;            // empty: none
  std::string token_source;     // "--token-file F", "$EDM_TOKEN_FILE F", "$EDM_TOKEN" or ""
  std::string tls_ca_file;      // TLS on when this or tls_fingerprint is set
  std::string tls_fingerprint;  // SHA-256, hex, colons optional
};

/// A bad flag value, an unreadable or empty token file. what() is the whole message.
class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The command-line values (empty: not given) and an environment lookup (tests pass their own).
struct ConnectionFlags {
  std::string host;
  std::string port;
  std::string token_file;
  std::string tls_ca_file;
  std::string tls_fingerprint;
};
using EnvLookup = const char* (*)(const char* name);

/// Resolves the settings in the order above. Throws SettingsError.
ConnectionSettings resolve_connection(const ConnectionFlags& flags, EnvLookup env);

/// The client library's options for these settings (host, port, token, TLS).
bridge::ClientOptions client_options(const ConnectionSettings& s);

/// Reads a token file: the first line, trimmed; refuses a missing, unreadable or empty file.
std::string read_token_file(const std::string& path);

/// "1..65535" → port; throws SettingsError naming `what`.
std::uint16_t parse_port(std::string_view text, std::string_view what);

}  // namespace edm::hmi
