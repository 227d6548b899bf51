#pragma once
// The hal driver's pin map (`machine.io.pins`, docs/hal.md): for each io.<name> of the process
// image, the HAL pin `<component>.<hal>` it is, its HAL type and direction, scaling
// (engineering = raw · scale + offset), a free-running counter read as its change per cycle, the
// value held in the safe state, an optional signal the driver links it to, and its role (the
// HAL side's heartbeat, or edmplc's own). parse_pin_entry() is non-RT.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/hal/component.hpp"
#include "edm/runtime/io_driver.hpp"

namespace edm::hal {

/// Which safe states hold an output at `safe`: FAULT and ESTOP (the generator), or ESTOP only
/// (axis velocities: in FAULT the programs back Z off through them).
enum class SafeIn : std::uint8_t { kFaultAndEstop, kEstopOnly };
enum class Role : std::uint8_t {
  kNone,
  kHeartbeat,     // an input that changes every HAL-side cycle; stale → alarm 121
  kHeartbeatOut,  // an output edmplc increments every cycle (the HAL side's watchdog)
};

/// The process image's type of the io pin.
enum class IoType : std::uint8_t { kBool, kReal, kInt };

struct HalPin {
  std::string name;    // io.<name>
  std::string hal;     // <component>.<hal>
  std::string signal;  // "" = not linked by the driver (a .hal file nets it)
  HalType type{HalType::kFloat};
  bool input{true};  // true: an input of the machine (HAL_IN of this component)
  double scale{1.0};
  double offset{0.0};
  bool counter{false};  // s32/u32 input: io pin = change since the last cycle (wraps mod 2^32)
  double safe{0.0};
  SafeIn safe_in{SafeIn::kFaultAndEstop};
  Role role{Role::kNone};
  std::string unit;
  [[nodiscard]] IoType io_type() const noexcept;
};

/// Reads one entry; problems are appended to errs (entry `index`, at the key). Non-RT.
HalPin parse_pin_entry(const rt::PinMapEntry& entry, std::size_t index,
                       std::vector<rt::PinMapError>& errs);
/// The whole map: entries, then duplicates (io name, HAL name, a second heartbeat). Non-RT.
std::vector<HalPin> parse_pin_map(const std::vector<rt::PinMapEntry>& entries,
                                  std::vector<rt::PinMapError>& errs);

/// Engineering value → the raw value a HAL pin takes (s32/u32 rounded and clamped; a non-finite
/// value writes 0). RT-safe.
[[nodiscard]] double to_raw(const HalPin& p, double value) noexcept;

}  // namespace edm::hal
