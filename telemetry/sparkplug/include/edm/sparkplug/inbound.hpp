#pragma once
// What a Sparkplug B payload from the broker must pass before it is decoded (docs/security.md
// "MQTT"): a size limit, then a walk of its protobuf wire format that counts the metrics and
// checks the framing without decoding or allocating, so a 100k-metric or 8 MB payload costs a
// scan and a counter, never 100k objects or an 8 MB log line. decode() runs only after it.
// RT-safe in the narrow sense (no allocation, lock or syscall), but it is only ever called on
// non-RT threads. Thread-safe (pure).

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace edm::sparkplug {

struct InboundLimits {
  /// Bytes of one NCMD/DCMD payload (mqtt.limits.max_payload_bytes).
  std::size_t max_payload_bytes{64 * 1024};
  /// Metrics of one NCMD/DCMD (mqtt.limits.max_metrics).
  std::size_t max_metrics{256};
};

enum class Screen : std::uint8_t {
  kOk,
  kTooLarge,        // over max_payload_bytes: not looked into
  kTooManyMetrics,  // over max_metrics
  kMalformed,       // not protobuf framing of a Payload (truncated, bad varint, groups, field 0)
};

struct ScreenResult {
  Screen verdict{Screen::kOk};
  std::size_t bytes{0};
  std::size_t metrics{0};  // counted up to the end, also past the limit (for the log line)
};

/// Checks `bytes` against `limits` and the Payload's top-level framing.
ScreenResult screen_payload(std::string_view bytes, const InboundLimits& limits) noexcept;

}  // namespace edm::sparkplug
