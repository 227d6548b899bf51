#include "edm/sparkplug/sparkplug.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "sparkplug_b.pb.h"

namespace edm::sparkplug {

namespace {

constexpr std::array<std::pair<MessageType, std::string_view>, 9> kTypeNames{{
    {MessageType::kNBirth, "NBIRTH"},
    {MessageType::kNDeath, "NDEATH"},
    {MessageType::kNData, "NDATA"},
    {MessageType::kNCmd, "NCMD"},
    {MessageType::kDBirth, "DBIRTH"},
    {MessageType::kDDeath, "DDEATH"},
    {MessageType::kDData, "DDATA"},
    {MessageType::kDCmd, "DCMD"},
    {MessageType::kState, "STATE"},
}};

bool is_device_type(MessageType t) noexcept {
  return t == MessageType::kDBirth || t == MessageType::kDDeath || t == MessageType::kDData ||
         t == MessageType::kDCmd;
}

void put_value(pb::Payload::Metric& m, DataType type, const Value& v) {
  if (std::holds_alternative<std::monostate>(v)) {
    m.set_is_null(true);
    return;
  }
  const auto as_i64 = [&]() -> std::int64_t {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
    if (const auto* u = std::get_if<std::uint64_t>(&v)) return static_cast<std::int64_t>(*u);
    if (const auto* d = std::get_if<double>(&v)) return static_cast<std::int64_t>(std::llround(*d));
    if (const auto* b = std::get_if<bool>(&v)) return *b ? 1 : 0;
    return 0;
  };
  switch (type) {
    case DataType::kInt8:
    case DataType::kInt16:
    case DataType::kInt32:
    case DataType::kUInt8:
    case DataType::kUInt16:
    case DataType::kUInt32: m.set_int_value(static_cast<std::uint32_t>(as_i64())); break;
    case DataType::kInt64:
    case DataType::kUInt64:
    case DataType::kDateTime: m.set_long_value(static_cast<std::uint64_t>(as_i64())); break;
    case DataType::kFloat: m.set_float_value(static_cast<float>(as_double(v).value_or(0.0))); break;
    case DataType::kDouble: m.set_double_value(as_double(v).value_or(0.0)); break;
    case DataType::kBoolean: m.set_boolean_value(as_double(v).value_or(0.0) != 0.0); break;
    case DataType::kString:
    case DataType::kText:
    case DataType::kUnknown:
      if (const auto* s = std::get_if<std::string>(&v)) {
        m.set_string_value(*s);
      } else {
        m.set_string_value(to_text(v));
      }
      break;
  }
}

Value get_value(const pb::Payload::Metric& m) {
  if (m.is_null()) return std::monostate{};
  const auto type = static_cast<DataType>(m.datatype());
  switch (m.value_case()) {
    case pb::Payload::Metric::kIntValue:
      switch (type) {
        case DataType::kInt8:
          return static_cast<std::int64_t>(static_cast<std::int8_t>(m.int_value()));
        case DataType::kInt16:
          return static_cast<std::int64_t>(static_cast<std::int16_t>(m.int_value()));
        case DataType::kInt32:
          return static_cast<std::int64_t>(static_cast<std::int32_t>(m.int_value()));
        default: return static_cast<std::uint64_t>(m.int_value());
      }
    case pb::Payload::Metric::kLongValue:
      if (type == DataType::kInt64) return static_cast<std::int64_t>(m.long_value());
      return m.long_value();
    case pb::Payload::Metric::kFloatValue: return static_cast<double>(m.float_value());
    case pb::Payload::Metric::kDoubleValue: return m.double_value();
    case pb::Payload::Metric::kBooleanValue: return m.boolean_value();
    case pb::Payload::Metric::kStringValue: return m.string_value();
    case pb::Payload::Metric::kBytesValue: return m.bytes_value();
    case pb::Payload::Metric::VALUE_NOT_SET: break;
  }
  return std::monostate{};
}

// Whether a decoded metric's value is in the wire field its datatype names, within its range.
bool value_fits(const pb::Payload::Metric& m) {
  if (m.is_null()) return true;
  using M = pb::Payload::Metric;
  const auto as_i32 = [&] { return static_cast<std::int32_t>(m.int_value()); };
  switch (m.datatype()) {
    case pb::Int8: return m.value_case() == M::kIntValue && as_i32() >= -128 && as_i32() <= 127;
    case pb::Int16:
      return m.value_case() == M::kIntValue && as_i32() >= -32768 && as_i32() <= 32767;
    case pb::Int32:
    case pb::UInt32: return m.value_case() == M::kIntValue;
    case pb::UInt8: return m.value_case() == M::kIntValue && m.int_value() <= 0xFFu;
    case pb::UInt16: return m.value_case() == M::kIntValue && m.int_value() <= 0xFFFFu;
    case pb::Int64:
    case pb::UInt64:
    case pb::DateTime: return m.value_case() == M::kLongValue;
    case pb::Float: return m.value_case() == M::kFloatValue;
    case pb::Double: return m.value_case() == M::kDoubleValue;
    case pb::Boolean: return m.value_case() == M::kBooleanValue;
    case pb::String:
    case pb::Text:
    case pb::UUID: return m.value_case() == M::kStringValue;
    case pb::Bytes:
    case pb::File: return m.value_case() == M::kBytesValue;
    default:  // Unknown, DataSet, Template, PropertySet…: no scalar value here
      return false;
  }
}

}  // namespace

std::string_view to_string(MessageType t) noexcept {
  for (const auto& [type, name] : kTypeNames) {
    if (type == t) return name;
  }
  return "?";
}

std::string_view to_string(DataType t) noexcept {
  switch (t) {
    case DataType::kInt8: return "Int8";
    case DataType::kInt16: return "Int16";
    case DataType::kInt32: return "Int32";
    case DataType::kInt64: return "Int64";
    case DataType::kUInt8: return "UInt8";
    case DataType::kUInt16: return "UInt16";
    case DataType::kUInt32: return "UInt32";
    case DataType::kUInt64: return "UInt64";
    case DataType::kFloat: return "Float";
    case DataType::kDouble: return "Double";
    case DataType::kBoolean: return "Boolean";
    case DataType::kString: return "String";
    case DataType::kDateTime: return "DateTime";
    case DataType::kText: return "Text";
    case DataType::kUnknown: break;
  }
  return "Unknown";
}

std::string Topic::str() const {
  std::string t;
  t.reserve(kNamespace.size() + group.size() + node.size() + device.size() + 12);
  t.append(kNamespace).append("/").append(group).append("/").append(to_string(type));
  t.append("/").append(node);
  if (!device.empty()) t.append("/").append(device);
  return t;
}

bool valid_id(std::string_view id) noexcept {
  return !id.empty() && id.find_first_of("/+#") == std::string_view::npos;
}

std::optional<Topic> parse_topic(std::string_view topic) {
  std::vector<std::string_view> parts;
  while (true) {
    const auto slash = topic.find('/');
    parts.push_back(topic.substr(0, slash));
    if (slash == std::string_view::npos) break;
    topic.remove_prefix(slash + 1);
  }
  if (parts.size() < 3 || parts[0] != kNamespace) return std::nullopt;
  Topic t;
  if (parts[1] == "STATE" && parts.size() == 3) {  // spBv1.0/STATE/<host_id>
    t.type = MessageType::kState;
    t.group = std::string(parts[2]);
    return t;
  }
  if (parts.size() < 4 || parts.size() > 5) return std::nullopt;
  bool found = false;
  for (const auto& [type, name] : kTypeNames) {
    if (name == parts[2] && type != MessageType::kState) {
      t.type = type;
      found = true;
    }
  }
  if (!found || (parts.size() == 5) != is_device_type(t.type)) return std::nullopt;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    if (i != 2 && !valid_id(parts[i])) return std::nullopt;
  }
  t.group = std::string(parts[1]);
  t.node = std::string(parts[3]);
  if (parts.size() == 5) t.device = std::string(parts[4]);
  return t;
}

const Metric* Payload::find(std::string_view name) const noexcept {
  for (const auto& m : metrics) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::string encode(const Payload& p) {
  pb::Payload out;
  out.set_timestamp(p.timestamp);
  if (p.seq) out.set_seq(*p.seq);
  for (const Metric& m : p.metrics) {
    pb::Payload::Metric* pm = out.add_metrics();
    if (!m.name.empty()) pm->set_name(m.name);
    pm->set_timestamp(m.timestamp);
    pm->set_datatype(static_cast<std::uint32_t>(m.type));
    if (m.historical) pm->set_is_historical(true);
    if (m.transient) pm->set_is_transient(true);
    put_value(*pm, m.type, m.value);
  }
  return out.SerializeAsString();
}

std::optional<Payload> decode(std::string_view bytes) {
  pb::Payload in;
  if (!in.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) return std::nullopt;
  Payload p;
  p.timestamp = in.timestamp();
  if (in.has_seq()) p.seq = in.seq();
  p.metrics.reserve(static_cast<std::size_t>(in.metrics_size()));
  for (const auto& pm : in.metrics()) {
    Metric m;
    m.name = pm.name();
    m.type = static_cast<DataType>(pm.datatype());
    m.value = get_value(pm);
    m.timestamp = pm.timestamp();
    m.historical = pm.is_historical();
    m.transient = pm.is_transient();
    if (pm.has_alias()) m.alias = pm.alias();
    m.value_ok = value_fits(pm);
    p.metrics.push_back(std::move(m));
  }
  return p;
}

std::optional<double> as_double(const Value& v) noexcept {
  if (const auto* b = std::get_if<bool>(&v)) return *b ? 1.0 : 0.0;
  if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
  if (const auto* u = std::get_if<std::uint64_t>(&v)) return static_cast<double>(*u);
  if (const auto* d = std::get_if<double>(&v)) return *d;
  return std::nullopt;
}

std::string to_text(const Value& v) {
  if (std::holds_alternative<std::monostate>(v)) return "null";
  if (const auto* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  if (const auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (const auto* u = std::get_if<std::uint64_t>(&v)) return std::to_string(*u);
  if (const auto* d = std::get_if<double>(&v)) {
    std::array<char, 32> buf{};
    std::snprintf(buf.data(), buf.size(), "%.6g", *d);
    return buf.data();
  }
  return std::get<std::string>(v);
}

std::uint64_t now_ms() noexcept {
  const auto t = std::chrono::system_clock::now().time_since_epoch();
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::milliseconds>(t).count());
}

}  // namespace edm::sparkplug
