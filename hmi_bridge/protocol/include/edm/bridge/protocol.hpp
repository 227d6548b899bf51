#pragma once
// The HMI bridge protocol (DESIGN §9, docs/protocol.md): JSON Lines over TCP. This header holds
// what both ends share — version, limits, error codes, roles, topics — with no dependency on the
// runtime (the HMI process links it) and no I/O. The ops are the server's op table
// (edm/bridge/op_table.hpp); a client learns them from machine.info's "ops".
//
// Thread-safety: pure data and pure functions (thread-safe). Not for RT threads (the codec
// allocates).

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace edm::bridge {

inline constexpr int kProtocolVersion = 1;
inline constexpr std::uint16_t kDefaultPort = 7730;
/// Longest line either side accepts, newline excluded (DESIGN §9: 1 MiB).
inline constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;
/// Deepest nesting of arrays and objects a line may have (either side). Parsing is bounded by
/// it before any parser runs, so a hostile line cannot exhaust a stack.
inline constexpr int kMaxJsonDepth = 32;
/// Status subscription rates the server accepts (Hz).
inline constexpr int kMinRateHz = 1;
inline constexpr int kMaxRateHz = 100;
/// Most blocks one program may have (the same bound check_program() enforces).
inline constexpr std::size_t kMaxProgramBlocks = 1'000'000;
/// hello's optional "peer" (docs/protocol.md): the end client's address as a relaying HMI (edmhmi
/// serve) saw it, 1 to kMaxHelloPeerChars printable ASCII characters.
inline constexpr std::size_t kMaxHelloPeerChars = 64;
/// True for a valid hello "peer": 1 to kMaxHelloPeerChars bytes, each printable ASCII (0x20-0x7e).
bool valid_hello_peer(std::string_view peer) noexcept;

/// Stable error codes (the `error.code` string of a failed reply).
enum class ErrorCode : std::uint8_t {
  kBadJson,       // the line is not a JSON object
  kBadRequest,    // well-formed JSON, but a field is missing, of the wrong type or out of range
  kUnknownOp,     // `op` names no operation
  kUnauthorized,  // no hello yet, or a wrong token / protocol version
  kForbidden,     // the session's role may not do this (viewer)
  kInvalidState,  // the machine's state does not allow it (e.g. resume when idle)
  kNotFound,      // no such variable / upload
  kTooLarge,      // a line over the limit, or a program over kMaxProgramBlocks
  kBusy,          // the resource is in use (job running, queue full, too many sessions)
  kRetainFailed,  // the retained data could not be written: nothing changed (alarm 183)
};
inline constexpr int kErrorCodeCount = 10;

std::string_view to_string(ErrorCode c) noexcept;
bool error_code_from_string(std::string_view s, ErrorCode& out) noexcept;

enum class Role : std::uint8_t { kViewer, kOperator };
std::string_view to_string(Role r) noexcept;

/// Subscription topics.
inline constexpr std::string_view kTopicStatus = "status";
inline constexpr std::string_view kTopicAlarm = "alarm";
inline constexpr std::string_view kTopicProgress = "progress";

}  // namespace edm::bridge
