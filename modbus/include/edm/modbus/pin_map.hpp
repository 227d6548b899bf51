#pragma once
// The modbus driver's pin map (`machine.io.pins`, docs/modbus.md): which Modbus table and
// address each io.<pin> is, its type (int16/uint16/int32/uint32/float32, word order), scaling
// (engineering = raw · scale + offset), its value in the safe state and its safety role; and the
// conversions between engineering values and 16-bit registers, shared with the server.
// parse_pin_entry() is non-RT; decode()/encode() are RT-safe (pure, no allocation).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/io_driver.hpp"

namespace edm::modbus {

enum class Table : std::uint8_t { kCoil, kDiscreteInput, kInputRegister, kHoldingRegister };
enum class ValueType : std::uint8_t { kBool, kInt16, kUint16, kInt32, kUint32, kFloat32 };
/// 32-bit values: kBig = high word at the lower address (the Modbus convention, "ABCD"),
/// kLittle = low word first ("CDAB"). Bytes within a register are always big-endian.
enum class WordOrder : std::uint8_t { kBig, kLittle };
/// What an input means to the machine's safety chain (normally-closed contacts: true = OK).
enum class SafetyRole : std::uint8_t { kNone, kEstop, kInterlock };

std::string_view to_string(Table t) noexcept;
std::string_view to_string(ValueType t) noexcept;

[[nodiscard]] constexpr bool is_bit_table(Table t) noexcept {
  return t == Table::kCoil || t == Table::kDiscreteInput;
}
/// Registers a value takes (bits: 1 bit).
[[nodiscard]] constexpr std::uint16_t words_of(ValueType t) noexcept {
  return t == ValueType::kInt32 || t == ValueType::kUint32 || t == ValueType::kFloat32 ? 2 : 1;
}

/// How a number maps onto registers.
struct Encoding {
  ValueType type{ValueType::kUint16};
  WordOrder order{WordOrder::kBig};
  double scale{1.0};
  double offset{0.0};
};

struct PinMapping {
  std::string name;  // io.<name>
  Table table{Table::kCoil};
  bool input{false};  // true: read from the remote I/O (an input of the machine)
  std::uint16_t address{0};
  Encoding enc;
  std::string unit;
  double safe{0.0};  // outputs: the value held in FAULT/ESTOP and when edmplc stops
  SafetyRole safety{SafetyRole::kNone};
};

/// Reads one entry; problems are appended to errs (entry index `index`). Non-RT.
PinMapping parse_pin_entry(const rt::PinMapEntry& entry, std::size_t index,
                           std::vector<rt::PinMapError>& errs);
/// Reads a `{type, word_order, scale, offset}` field set (the server's variables use it too);
/// returns false after appending an error. Non-RT.
bool parse_encoding_field(const rt::PinMapField& f, Encoding& enc, std::string& error);

/// Registers → engineering value (raw · scale + offset). RT-safe.
[[nodiscard]] double decode(const std::uint16_t* words, const Encoding& enc) noexcept;
/// Engineering value → registers: (v − offset) / scale, rounded and clamped to the type's range
/// (a non-finite value writes 0). Returns false when it had to clamp or replace. RT-safe.
bool encode(double value, const Encoding& enc, std::uint16_t* words) noexcept;

}  // namespace edm::modbus
