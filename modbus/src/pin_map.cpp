#include "edm/modbus/pin_map.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "edm/machining/located_yaml.hpp"

namespace edm::modbus {

namespace {

std::optional<double> number(const rt::PinMapField& f) {
  double v = 0.0;
  const char* b = f.value.data();
  const char* e = b + f.value.size();
  auto [p, ec] = std::from_chars(b, e, v);
  if (f.quoted || ec != std::errc{} || p != e || f.value.empty() || !std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> integer(const rt::PinMapField& f) {
  std::int64_t v = 0;
  const char* b = f.value.data();
  const char* e = b + f.value.size();
  auto [p, ec] = std::from_chars(b, e, v);
  if (f.quoted || ec != std::errc{} || p != e || f.value.empty()) {
    return std::nullopt;
  }
  return v;
}

struct RawRange {
  double lo;
  double hi;
};

RawRange range_of(ValueType t) noexcept {
  switch (t) {
    case ValueType::kBool: return {0, 1};
    case ValueType::kInt16: return {-32768.0, 32767.0};
    case ValueType::kUint16: return {0.0, 65535.0};
    case ValueType::kInt32: return {-2147483648.0, 2147483647.0};
    case ValueType::kUint32: return {0.0, 4294967295.0};
    case ValueType::kFloat32:
      return {-static_cast<double>(std::numeric_limits<float>::max()),
              static_cast<double>(std::numeric_limits<float>::max())};
  }
  return {0, 0};
}

}  // namespace

std::string_view to_string(Table t) noexcept {
  switch (t) {
    case Table::kCoil: return "coil";
    case Table::kDiscreteInput: return "discrete_input";
    case Table::kInputRegister: return "input_register";
    case Table::kHoldingRegister: return "holding_register";
  }
  return "?";
}

std::string_view to_string(ValueType t) noexcept {
  switch (t) {
    case ValueType::kBool: return "bool";
    case ValueType::kInt16: return "int16";
    case ValueType::kUint16: return "uint16";
    case ValueType::kInt32: return "int32";
    case ValueType::kUint32: return "uint32";
    case ValueType::kFloat32: return "float32";
  }
  return "?";
}

bool parse_encoding_field(const rt::PinMapField& f, Encoding& enc, std::string& error) {
  if (f.key == "type") {
    static constexpr std::array<std::pair<std::string_view, ValueType>, 5> kTypes{{
        {"int16", ValueType::kInt16},
        {"uint16", ValueType::kUint16},
        {"int32", ValueType::kInt32},
        {"uint32", ValueType::kUint32},
        {"float32", ValueType::kFloat32},
    }};
    for (const auto& t : kTypes) {
      if (f.value == t.first) {
        enc.type = t.second;
        return true;
      }
    }
    error = "unknown type " + machining::yaml::quote(f.value) +
            " (int16, uint16, int32, uint32, float32)";
    return false;
  }
  if (f.key == "word_order") {
    if (f.value == "big" || f.value == "little") {
      enc.order = f.value == "big" ? WordOrder::kBig : WordOrder::kLittle;
      return true;
    }
    error = "must be big (high word first) or little, got " + machining::yaml::quote(f.value);
    return false;
  }
  if (f.key == "scale" || f.key == "offset") {
    const auto v = number(f);
    if (!v || (f.key == "scale" && *v == 0.0)) {
      error = f.key == "scale"
                  ? "must be a finite number other than 0, got " + machining::yaml::quote(f.value)
                  : "must be a finite number, got " + machining::yaml::quote(f.value);
      return false;
    }
    (f.key == "scale" ? enc.scale : enc.offset) = *v;
    return true;
  }
  error = "not an encoding key";
  return false;
}

PinMapping parse_pin_entry(const rt::PinMapEntry& entry, std::size_t index,
                           std::vector<rt::PinMapError>& errs) {
  PinMapping m;
  const auto err = [&](const std::string& key, std::string message) {
    errs.push_back({index, key, std::move(message)});
  };
  bool has_name = false;
  bool has_table = false;
  bool table_seen = false;
  bool address_seen = false;
  std::optional<bool> direction;
  bool has_type = false;
  bool has_order = false;
  bool has_safety = false;
  for (const rt::PinMapField& f : entry) {
    std::string e;
    if (f.key == "name") {
      has_name = true;
      if (!machining::yaml::is_identifier(f.value)) {
        err(f.key, "pin name " + machining::yaml::quote(f.value) + " is not an identifier");
      }
      m.name = f.value;
    } else if (f.key == "table") {
      has_table = table_seen = true;
      if (f.value == "coil") {
        m.table = Table::kCoil;
      } else if (f.value == "discrete_input") {
        m.table = Table::kDiscreteInput;
      } else if (f.value == "input_register") {
        m.table = Table::kInputRegister;
      } else if (f.value == "holding_register") {
        m.table = Table::kHoldingRegister;
      } else {
        has_table = false;
        err(f.key, "unknown table " + machining::yaml::quote(f.value) +
                       " (coil, discrete_input, input_register, holding_register)");
      }
    } else if (f.key == "address") {
      address_seen = true;
      const auto a = integer(f);
      if (!a || *a < 0 || *a > 65535) {
        err(f.key, "must be a whole number in [0, 65535] (0-based), got " +
                       machining::yaml::quote(f.value));
      } else {
        m.address = static_cast<std::uint16_t>(*a);
      }
    } else if (f.key == "direction") {
      if (f.value == "in" || f.value == "out") {
        direction = f.value == "in";
      } else {
        err(f.key, "must be in or out, got " + machining::yaml::quote(f.value));
      }
    } else if (f.key == "type" || f.key == "word_order" || f.key == "scale" || f.key == "offset") {
      has_type = has_type || f.key == "type";
      has_order = has_order || f.key == "word_order";
      if (!parse_encoding_field(f, m.enc, e)) {
        err(f.key, e);
      }
    } else if (f.key == "unit") {
      m.unit = f.value;
    } else if (f.key == "safe") {
      if (!f.quoted && (f.value == "true" || f.value == "false")) {
        m.safe = f.value == "true" ? 1.0 : 0.0;
      } else if (const auto v = number(f)) {
        m.safe = *v;
      } else {
        err(f.key, "must be a number or true/false, got " + machining::yaml::quote(f.value));
      }
    } else if (f.key == "safety") {
      has_safety = true;
      if (f.value == "estop") {
        m.safety = SafetyRole::kEstop;
      } else if (f.value == "interlock") {
        m.safety = SafetyRole::kInterlock;
      } else {
        err(f.key, "must be estop or interlock, got " + machining::yaml::quote(f.value));
      }
    } else {
      err(f.key, "unknown key " + machining::yaml::quote(f.key) +
                     " (name, table, address, direction, type, word_order, scale, offset, unit, "
                     "safe, safety)");
    }
  }
  if (!has_name) {
    err("", "missing required key 'name'");
  }
  if (!table_seen) {
    err("", "missing required key 'table'");
  }
  if (!address_seen) {
    err("", "missing required key 'address'");
  }
  if (!has_table) {
    return m;
  }
  const bool read_only = m.table == Table::kDiscreteInput || m.table == Table::kInputRegister;
  m.input = direction.value_or(read_only);
  if (read_only && !m.input) {
    err("direction", std::string(to_string(m.table)) + " is read-only: direction must be in");
  }
  if (is_bit_table(m.table)) {
    if (has_type || has_order || m.enc.scale != 1.0 || m.enc.offset != 0.0) {
      err("", std::string(to_string(m.table)) +
                  " is a bit: type, word_order, scale and offset do not apply");
    }
    m.enc = Encoding{ValueType::kBool, WordOrder::kBig, 1.0, 0.0};
  } else if (has_order && words_of(m.enc.type) == 1) {
    err("word_order", "applies to 32-bit types only (int32, uint32, float32)");
  }
  if (has_safety && !(m.input && is_bit_table(m.table))) {
    err("safety",
        "only a bit input (discrete_input, or a coil read with direction: in) can be "
        "an estop or interlock contact");
  }
  if (m.input && m.safe != 0.0) {
    err("safe", "applies to outputs only");
  }
  if (!m.input && m.address + words_of(m.enc.type) - 1 > 65535) {
    err("address", "the value runs past register 65535");
  }
  return m;
}

double decode(const std::uint16_t* words, const Encoding& enc) noexcept {
  const std::uint16_t w0 = words[0];
  double raw = 0.0;
  if (words_of(enc.type) == 1) {
    raw = enc.type == ValueType::kInt16  ? static_cast<double>(static_cast<std::int16_t>(w0))
          : enc.type == ValueType::kBool ? (w0 != 0 ? 1.0 : 0.0)
                                         : static_cast<double>(w0);
  } else {
    const std::uint16_t hi = enc.order == WordOrder::kBig ? w0 : words[1];
    const std::uint16_t lo = enc.order == WordOrder::kBig ? words[1] : w0;
    const std::uint32_t u = (static_cast<std::uint32_t>(hi) << 16U) | lo;
    switch (enc.type) {
      case ValueType::kInt32: raw = static_cast<double>(static_cast<std::int32_t>(u)); break;
      case ValueType::kFloat32: raw = static_cast<double>(std::bit_cast<float>(u)); break;
      default: raw = static_cast<double>(u); break;
    }
  }
  return raw * enc.scale + enc.offset;
}

bool encode(double value, const Encoding& enc, std::uint16_t* words) noexcept {
  bool exact = std::isfinite(value);
  double raw = exact ? (value - enc.offset) / enc.scale : 0.0;
  if (!std::isfinite(raw)) {
    raw = 0.0;
    exact = false;
  }
  if (enc.type != ValueType::kFloat32) {
    raw = std::nearbyint(raw);
  }
  const RawRange r = range_of(enc.type);
  if (raw < r.lo || raw > r.hi) {
    raw = raw < r.lo ? r.lo : r.hi;
    exact = false;
  }
  std::uint32_t u = 0;
  switch (enc.type) {
    case ValueType::kBool:
    case ValueType::kUint16:
    case ValueType::kUint32: u = static_cast<std::uint32_t>(raw); break;
    case ValueType::kInt16: u = static_cast<std::uint16_t>(static_cast<std::int16_t>(raw)); break;
    case ValueType::kInt32: u = static_cast<std::uint32_t>(static_cast<std::int32_t>(raw)); break;
    case ValueType::kFloat32: u = std::bit_cast<std::uint32_t>(static_cast<float>(raw)); break;
  }
  if (words_of(enc.type) == 1) {
    words[0] = static_cast<std::uint16_t>(u);
  } else {
    const auto hi = static_cast<std::uint16_t>(u >> 16U);
    const auto lo = static_cast<std::uint16_t>(u & 0xFFFFU);
    words[0] = enc.order == WordOrder::kBig ? hi : lo;
    words[1] = enc.order == WordOrder::kBig ? lo : hi;
  }
  return exact;
}

}  // namespace edm::modbus
