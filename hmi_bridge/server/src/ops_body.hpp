#pragma once
// The helpers every op file shares (ops.cpp, ops_operator.cpp, ops_vars.cpp): an error body, a
// quoted client name, required fields. What an op returns (ops::Body) is op_table.hpp's. Server
// thread only.

#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "edm/bridge/codec.hpp"
#include "edm/bridge/op_table.hpp"
#include "edm/bridge/protocol.hpp"
#include "edm/runtime/log_escape.hpp"

namespace edm::bridge::ops {

inline Body error(ErrorCode code, std::string message, Json details = nullptr) {
  return Error{code, std::move(message), std::move(details)};
}

/// A client-supplied name quoted in a message: single quotes, escaped and cut at 64 bytes as in
/// a log line (rt::log_quote), never the client's JSON.
inline std::string brief_name(std::string_view name) {
  return rt::log_quote(name, rt::kLogQuoteMaxBytes, '\'');
}

/// Decodes a chunk's blocks into `out`, one at a time: the index of the first bad one (with
/// `why`), or nullopt. Stops at the first bad block, so memory grows with the valid blocks, never
/// with the element count of a hostile array ("[0,0,0,…]": 500,000 elements in a 1 MiB line).
inline std::optional<std::size_t> decode_blocks(const Json& blocks,
                                                std::vector<machining::MotionBlock>& out,
                                                std::string& why) {
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    machining::MotionBlock b;
    if (!from_json(blocks[i], b, why)) return i;
    out.push_back(b);
  }
  return std::nullopt;
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
