#include "edm/hmi/connection.hpp"

#include <charconv>

#include "edm/machining/bounded_read.hpp"

namespace edm::hmi {

namespace {

std::string trim(std::string s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

const char* env_or_null(EnvLookup env, const char* name) {
  if (env == nullptr) return nullptr;
  const char* v = env(name);
  return v != nullptr && *v != '\0' ? v : nullptr;
}

}  // namespace

std::uint16_t parse_port(std::string_view text, std::string_view what) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value < 1 || value > 65535) {
    throw SettingsError(std::string(what) + ": '" + std::string(text) +
                        "' is not a port number (1..65535)");
  }
  return static_cast<std::uint16_t>(value);
}

std::string read_token_file(const std::string& path) {
  // Bounded and regular files only: a FIFO or /dev/zero as --token-file cannot hang or fill us.
  const edm::machining::BoundedRead file =
      edm::machining::read_bounded_file(path, edm::machining::kMaxTokenFileBytes, "token file");
  if (!file.ok()) throw SettingsError("token file '" + path + "': cannot be read: " + file.problem);
  std::string line = file.text.substr(0, file.text.find('\n'));
  line = trim(line);
  if (line.empty()) throw SettingsError("token file '" + path + "': empty first line");
  return line;
}

bridge::ClientOptions client_options(const ConnectionSettings& s) {
  bridge::ClientOptions o;
  o.host = s.host;
  o.port = s.port;
  o.token = s.token;
  o.tls.enabled = !s.tls_ca_file.empty() || !s.tls_fingerprint.empty();
  o.tls.ca_file = s.tls_ca_file;
  o.tls.fingerprint = s.tls_fingerprint;
  return o;
}

ConnectionSettings resolve_connection(const ConnectionFlags& flags, EnvLookup env) {
  ConnectionSettings s;
  if (!flags.host.empty()) {
    s.host = flags.host;
  } else if (const char* h = env_or_null(env, "EDM_HOST")) {
    s.host = h;
  }
  if (!flags.port.empty()) {
    s.port = parse_port(flags.port, "--port");
  } else if (const char* p = env_or_null(env, "EDM_PORT")) {
    s.port = parse_port(p, "$EDM_PORT");
  }
  if (!flags.token_file.empty()) {
    s.token = read_token_file(flags.token_file);
    s.token_source = "--token-file " + flags.token_file;
  } else if (const char* f = env_or_null(env, "EDM_TOKEN_FILE")) {
    s.token = read_token_file(f);
    s.token_source = std::string("$EDM_TOKEN_FILE ") + f;
  } else if (const char* t = env_or_null(env, "EDM_TOKEN")) {
    s.token = trim(t);
    s.token_source = "$EDM_TOKEN";
  }
  s.tls_ca_file = flags.tls_ca_file;
  if (s.tls_ca_file.empty()) {
    if (const char* f = env_or_null(env, "EDM_TLS_CA")) s.tls_ca_file = f;
  }
  s.tls_fingerprint = flags.tls_fingerprint;
  if (s.tls_fingerprint.empty()) {
    if (const char* f = env_or_null(env, "EDM_TLS_FINGERPRINT")) s.tls_fingerprint = f;
  }
  if (!s.tls_ca_file.empty() && !s.tls_fingerprint.empty()) {
    throw SettingsError("give either a TLS CA file or a fingerprint, not both");
  }
  return s;
}

}  // namespace edm::hmi
