#pragma once
// What an op returns (a reply body or a protocol error) and the field helpers every op file
// shares (ops.cpp, ops_operator.cpp). Server thread only.

#include <string>
#include <string_view>
#include <variant>

#include "edm/bridge/codec.hpp"
#include "edm/bridge/protocol.hpp"

namespace edm::bridge::ops {

struct Error {
  ErrorCode code;
  std::string message;
  Json details{nullptr};
};

using Body = std::variant<Json, Error>;

inline Body error(ErrorCode code, std::string message, Json details = nullptr) {
  return Error{code, std::move(message), std::move(details)};
}

/// A client-supplied name quoted in a message: at most 64 characters, never the client's JSON.
inline std::string brief_name(std::string_view name) {
  constexpr std::size_t kMax = 64;
  std::string q = "'";
  q.append(name.substr(0, kMax));
  q += name.size() > kMax ? "…'" : "'";
  return q;
}

/// A required field satisfying `ok`, or nullptr.
template <class Pred>
const Json* field(const Json& msg, const char* key, Pred ok) {
  auto it = msg.find(key);
  if (it == msg.end() || !ok(*it)) {
    return nullptr;
  }
  return &*it;
}

}  // namespace edm::bridge::ops
