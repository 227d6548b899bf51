#include "edm/bridge/protocol.hpp"

#include <array>

#include "edm/machining/enum_names.hpp"

namespace edm::bridge {

namespace {

constexpr std::array<std::string_view, kErrorCodeCount> kErrorNames = {
    "bad_json",      "bad_request", "unknown_op", "unauthorized", "forbidden",
    "invalid_state", "not_found",   "too_large",  "busy",         "retain_failed"};

}  // namespace

std::string_view to_string(ErrorCode c) noexcept { return machining::enum_name(kErrorNames, c); }

bool error_code_from_string(std::string_view s, ErrorCode& out) noexcept {
  return machining::enum_from_name(kErrorNames, s, out);
}

std::string_view to_string(Role r) noexcept { return r == Role::kOperator ? "operator" : "viewer"; }

bool valid_hello_peer(std::string_view peer) noexcept {
  if (peer.empty() || peer.size() > kMaxHelloPeerChars) return false;
  for (const char ch : peer) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

}  // namespace edm::bridge
