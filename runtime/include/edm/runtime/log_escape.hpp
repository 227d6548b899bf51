#pragma once
// The one way untrusted text reaches a log line or an audit file (issue 31): quoted, escaped,
// bounded. A client-supplied name (a variable, an op, a metric, a peer) written raw could hold
// a newline that forges a whole line ("… op=estop -> ok"), terminal escapes, or a megabyte.
//
//   spdlog::warn("bridge: unknown variable {}", rt::log_quoted(name));  // "a\nb" → "a\x0ab"
//   std::string d = "name=" + rt::log_quote(name);
//
// Escaping: printable ASCII 0x20–0x7e is kept, except the quote character and the backslash,
// which become \" (or \') and \\; every other byte — control characters, newlines, DEL,
// every byte of a non-ASCII (UTF-8) character — becomes \xNN (two lower-case hex digits). So
// the result is printable ASCII, never holds an unescaped quote, and decodes back unambiguously.
// Bounded: at most `max_bytes` bytes of the input are shown; a longer text gets "…" after its
// closing quote (outside the quotes, so no input can imitate a cut).
//
// Used by the bridge (hmi_bridge), the Modbus server (modbus/) and the MQTT publisher
// (telemetry/), which all depend on runtime.
// Thread-safety: pure functions (thread-safe). Not RT-safe (log_quote allocates; the fmt
// formatter of LogQuoted does not allocate by itself but runs inside spdlog, which may).

#include <fmt/format.h>

#include <cstddef>
#include <string>
#include <string_view>

namespace edm::rt {

/// Input bytes shown of one untrusted name by default.
inline constexpr std::size_t kLogQuoteMaxBytes = 64;

/// Appends `text` quoted and escaped (see above) to `out`.
void append_log_quoted(std::string& out, std::string_view text,
                       std::size_t max_bytes = kLogQuoteMaxBytes, char quote = '"');

/// `text` quoted and escaped (see above): "name", "a\x0ab", "first 64 bytes"….
[[nodiscard]] std::string log_quote(std::string_view text,
                                    std::size_t max_bytes = kLogQuoteMaxBytes, char quote = '"');

/// For fmt/spdlog arguments: formats as log_quote(text, max_bytes, quote) without a temporary.
/// `text` must outlive the formatting call.
struct LogQuoted {
  std::string_view text;
  std::size_t max_bytes{kLogQuoteMaxBytes};
  char quote{'"'};
};
[[nodiscard]] inline LogQuoted log_quoted(std::string_view text,
                                          std::size_t max_bytes = kLogQuoteMaxBytes) noexcept {
  return LogQuoted{text, max_bytes, '"'};
}

/// True when every byte of `text` is printable ASCII (0x20–0x7e).
[[nodiscard]] bool is_printable_ascii(std::string_view text) noexcept;

}  // namespace edm::rt

template <>
struct fmt::formatter<edm::rt::LogQuoted> : fmt::formatter<std::string_view> {
  template <class FormatContext>
  auto format(const edm::rt::LogQuoted& q, FormatContext& ctx) const {
    std::string s;
    edm::rt::append_log_quoted(s, q.text, q.max_bytes, q.quote);
    return fmt::formatter<std::string_view>::format(std::string_view(s), ctx);
  }
};
