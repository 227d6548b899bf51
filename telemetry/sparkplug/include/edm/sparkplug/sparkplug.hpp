#pragma once
// Sparkplug B (Eclipse Sparkplug 3.0.0) in plain C++: the topic namespace
// `spBv1.0/<group>/<type>/<node>[/<device>]`, metric values, and payload encoding/decoding through
// the protobuf schema telemetry/proto/sparkplug_b.proto. No MQTT here (edge_node.hpp, fleet.hpp).
// Non-RT (allocates); thread-compatible.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace edm::sparkplug {

inline constexpr std::string_view kNamespace = "spBv1.0";
/// Metric names the specification fixes.
inline constexpr std::string_view kBdSeq = "bdSeq";
inline constexpr std::string_view kRebirth = "Node Control/Rebirth";

enum class MessageType : std::uint8_t {
  kNBirth,
  kNDeath,
  kNData,
  kNCmd,
  kDBirth,
  kDDeath,
  kDData,
  kDCmd,
  kState,
};
std::string_view to_string(MessageType t) noexcept;

/// Metric.datatype (the specification's numbering).
enum class DataType : std::uint32_t {
  kUnknown = 0,
  kInt8 = 1,
  kInt16 = 2,
  kInt32 = 3,
  kInt64 = 4,
  kUInt8 = 5,
  kUInt16 = 6,
  kUInt32 = 7,
  kUInt64 = 8,
  kFloat = 9,
  kDouble = 10,
  kBoolean = 11,
  kString = 12,
  kDateTime = 13,
  kText = 14,
};
std::string_view to_string(DataType t) noexcept;

struct Topic {
  std::string group;
  MessageType type{MessageType::kNData};
  std::string node;
  std::string device;  // empty for node-level messages
  /// "spBv1.0/group/TYPE/node[/device]".
  [[nodiscard]] std::string str() const;
};
/// Parses a Sparkplug B topic; nullopt when it is not one (STATE: group holds the host id).
std::optional<Topic> parse_topic(std::string_view topic);
/// Group, node and device ids: non-empty UTF-8 without '/', '+' or '#'.
bool valid_id(std::string_view id) noexcept;

/// A metric's value: integers (signed and unsigned kept in 64 bits), reals, booleans, strings.
using Value = std::variant<std::monostate, bool, std::int64_t, std::uint64_t, double, std::string>;

struct Metric {
  std::string name;
  DataType type{DataType::kUnknown};
  Value value;                 // monostate: null (is_null on the wire)
  std::uint64_t timestamp{0};  // ms since the epoch (UTC)
  bool historical{false};
  bool transient{false};
  // Decoded only (encode() ignores them):
  std::optional<std::uint64_t> alias;  // edmplc defines no aliases
  /// The value came in the wire field its datatype names and fits that datatype (an Int8 in
  /// [-128, 127], …), or is_null. False for an unknown or unmodelled datatype (DataSet, …).
  bool value_ok{true};
};

struct Payload {
  std::uint64_t timestamp{0};
  std::optional<std::uint64_t> seq;  // absent in NDEATH
  std::vector<Metric> metrics;

  [[nodiscard]] const Metric* find(std::string_view name) const noexcept;
};

/// Protobuf bytes of a payload (values converted to the metric's datatype's wire field).
std::string encode(const Payload& p);
/// The payload of protobuf bytes; nullopt when they do not parse. Bytes from the broker pass
/// screen_payload() (inbound.hpp) first.
std::optional<Payload> decode(std::string_view bytes);

/// The value as a double (booleans 0/1); nullopt for strings and nulls.
std::optional<double> as_double(const Value& v) noexcept;
/// A short text for logs and the fleet view ("12.5", "true", "RUNNING", "null").
std::string to_text(const Value& v);

/// Milliseconds since the epoch, UTC (the system clock).
std::uint64_t now_ms() noexcept;

}  // namespace edm::sparkplug
