#include "edm/bridge/protocol.hpp"

#include <array>

namespace edm::bridge {

namespace {

constexpr std::array<std::string_view, kErrorCodeCount> kErrorNames = {
    "bad_json",      "bad_request", "unknown_op", "unauthorized", "forbidden",
    "invalid_state", "not_found",   "too_large",  "busy"};

constexpr std::array<OpInfo, 24> kOps = {{
    {"hello", false},        {"ping", false},          {"status", false},
    {"subscribe", false},    {"unsubscribe", false},   {"program.begin", true},
    {"program.chunk", true}, {"program.commit", true}, {"program.abort", true},
    {"cycle.start", true},   {"cycle.hold", true},     {"cycle.resume", true},
    {"cycle.stop", true},    {"estop", true},          {"reset", true},
    {"var.list", false},     {"var.read", false},      {"var.write", true},
    {"var.force", true},     {"var.unforce", true},    {"tasks.stats", false},
    {"trace.start", false},  {"trace.stop", false},    {"machine.info", false},
}};

}  // namespace

std::string_view to_string(ErrorCode c) noexcept {
  const auto i = static_cast<std::size_t>(c);
  return i < kErrorNames.size() ? kErrorNames[i] : std::string_view{"?"};
}

bool error_code_from_string(std::string_view s, ErrorCode& out) noexcept {
  for (std::size_t i = 0; i < kErrorNames.size(); ++i) {
    if (kErrorNames[i] == s) {
      out = static_cast<ErrorCode>(i);
      return true;
    }
  }
  return false;
}

std::string_view to_string(Role r) noexcept { return r == Role::kOperator ? "operator" : "viewer"; }

std::span<const OpInfo> all_ops() noexcept { return kOps; }

const OpInfo* find_op(std::string_view name) noexcept {
  for (const auto& op : kOps) {
    if (op.name == name) {
      return &op;
    }
  }
  return nullptr;
}

}  // namespace edm::bridge
