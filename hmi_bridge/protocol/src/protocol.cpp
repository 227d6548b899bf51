#include "edm/bridge/protocol.hpp"

#include <array>

#include "edm/machining/enum_names.hpp"

namespace edm::bridge {

namespace {

constexpr std::array<std::string_view, kErrorCodeCount> kErrorNames = {
    "bad_json",      "bad_request", "unknown_op", "unauthorized", "forbidden",
    "invalid_state", "not_found",   "too_large",  "busy",         "retain_failed"};

constexpr std::array<OpInfo, 32> kOps = {{
    {"hello", false},        {"ping", false},          {"status", false},
    {"subscribe", false},    {"unsubscribe", false},   {"program.begin", true},
    {"program.chunk", true}, {"program.commit", true}, {"program.abort", true},
    {"cycle.start", true},   {"cycle.hold", true},     {"cycle.resume", true},
    {"cycle.stop", true},    {"estop", true},          {"reset", true},
    {"var.list", false},     {"var.read", false},      {"var.write", true},
    {"var.force", true},     {"var.unforce", true},    {"tasks.stats", false},
    {"trace.start", false},  {"trace.stop", false},    {"machine.info", false},
    {"feed.override", true}, {"home", true},           {"jog", true},
    {"jog.stop", true},      {"touch", true},          {"manual.status", false},
    {"offset.get", false},   {"offset.set", true},
}};

}  // namespace

std::string_view to_string(ErrorCode c) noexcept { return machining::enum_name(kErrorNames, c); }

bool error_code_from_string(std::string_view s, ErrorCode& out) noexcept {
  return machining::enum_from_name(kErrorNames, s, out);
}

std::string_view to_string(Role r) noexcept { return r == Role::kOperator ? "operator" : "viewer"; }

std::span<const OpInfo> all_ops() noexcept { return kOps; }

bool valid_hello_peer(std::string_view peer) noexcept {
  if (peer.empty() || peer.size() > kMaxHelloPeerChars) return false;
  for (const char ch : peer) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

const OpInfo* find_op(std::string_view name) noexcept {
  for (const auto& op : kOps) {
    if (op.name == name) {
      return &op;
    }
  }
  return nullptr;
}

}  // namespace edm::bridge
