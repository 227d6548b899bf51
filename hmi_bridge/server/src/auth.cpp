#include "edm/bridge/auth.hpp"

#include <sys/stat.h>

#include <boost/asio/ip/address.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

namespace edm::bridge {

void check_private_file(const std::string& path, std::string_view key) {
  const std::string where = "bridge." + std::string(key) + " " + path + ": ";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw BridgeError(where + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    throw BridgeError(where + "not a regular file");
  }
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw BridgeError(where + "readable or writable by group/others (mode " + mode +
                      "); chmod 600 it");
  }
}

std::string read_token_file(const std::string& path, std::string_view key) {
  const std::string where = "bridge." + std::string(key) + " " + path + ": ";
  check_private_file(path, key);
  std::ifstream in(path);
  std::string line;
  // A token is one short line: read at most a bounded prefix whatever the file holds.
  constexpr std::size_t kMaxRead = 4096;
  std::string head(kMaxRead, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (!in && !in.eof()) {
    throw BridgeError(where + "cannot read a token from it");
  }
  line = head.substr(0, head.find('\n'));
  const auto first = line.find_first_not_of(" \t\r\n");
  const auto last = line.find_last_not_of(" \t\r\n");
  if (first == std::string::npos) {
    throw BridgeError(where + "the token is empty");
  }
  line = line.substr(first, last - first + 1);
  if (line.size() < kMinTokenChars) {
    throw BridgeError(where + "the token has " + std::to_string(line.size()) +
                      " characters; at least " + std::to_string(kMinTokenChars) +
                      " are required (e.g. openssl rand -hex 16)");
  }
  if (line.size() > kMaxTokenChars) {
    throw BridgeError(where + "the token is longer than " + std::to_string(kMaxTokenChars) +
                      " characters");
  }
  return line;
}

TokenSet load_tokens(const std::string& operator_file, const std::string& viewer_file) {
  TokenSet t;
  if (!operator_file.empty()) {
    t.operator_token = read_token_file(operator_file, "token_file");
  }
  if (!viewer_file.empty()) {
    t.viewer_token = read_token_file(viewer_file, "viewer_token_file");
  }
  if (!t.operator_token.empty() && t.operator_token == t.viewer_token) {
    throw BridgeError("bridge: token_file and viewer_token_file hold the same token");
  }
  return t;
}

bool constant_time_equal(std::string_view a, std::string_view b) noexcept {
  // Walk all of `a` (the secret) whatever b is; fold the length difference into the result.
  volatile unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const unsigned char x = static_cast<unsigned char>(a[i]);
    const unsigned char y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    diff = static_cast<unsigned char>(diff | (x ^ y));
  }
  return diff == 0;
}

std::optional<Role> authenticate(const TokenSet& tokens, std::string_view token,
                                 bool client_is_loopback) noexcept {
  if (!tokens.any()) {
    return client_is_loopback ? std::optional<Role>(Role::kOperator) : std::nullopt;
  }
  // Both comparisons always run, so the timing says nothing about which role matched.
  const bool op =
      !tokens.operator_token.empty() && constant_time_equal(tokens.operator_token, token);
  const bool viewer =
      !tokens.viewer_token.empty() && constant_time_equal(tokens.viewer_token, token);
  if (op) {
    return Role::kOperator;
  }
  if (viewer) {
    return Role::kViewer;
  }
  return std::nullopt;
}

bool is_loopback_address(const std::string& address) noexcept {
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(address, ec);
  if (ec) {
    return false;
  }
  if (a.is_v6() && a.to_v6().is_v4_mapped()) {
    return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, a.to_v6()).is_loopback();
  }
  return a.is_loopback();
}

}  // namespace edm::bridge
