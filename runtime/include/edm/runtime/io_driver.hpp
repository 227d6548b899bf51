#pragma once
// The I/O-driver interface: the process image's producer and consumer.
//
// A driver is a Block whose pins are the process image: its Output pins are the machine's inputs
// (%I: latched by read_inputs() at cycle start) and its Input pins are the machine's outputs
// (%Q: wired from program outputs, read by write_outputs() at cycle end). In YAML they are
// named io.<pin>. One task (machine.io.task, default the highest-priority one) owns the driver:
// its thread is the only one that calls read_inputs/write_outputs/enter_safe_state.
//
// update() is unused for drivers: the work is in read_inputs() and write_outputs().

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::rt {

/// A fault reported by a driver (code 0 = none). Text is static.
struct IoFault {
  int code{0};
  const char* text{""};
};

/// One `key: value` of a pin-map entry (`machine.io.pins[i]`), the scalar's text as written.
struct PinMapField {
  std::string key;
  std::string value;
  bool quoted{false};  // written quoted: a string, whatever its text
};
using PinMapEntry = std::vector<PinMapField>;

/// A problem with entry `entry` of a pin map: at its key `key` ("" = the entry as a whole).
struct PinMapError {
  std::size_t entry{0};
  std::string key;
  std::string message;
};

class IoDriver : public Block {
 public:
  /// Latches inputs into the driver's Output pins. RT-safe.
  virtual void read_inputs(const CycleContext& ctx) noexcept = 0;
  /// Publishes the driver's Input pins to the machine. In FAULT/ESTOP the driver must keep the
  /// machine safe whatever the pins say (generator off; axes stopped). RT-safe.
  virtual void write_outputs(const CycleContext& ctx) noexcept = 0;
  /// The driver's current fault, if any. RT-safe.
  [[nodiscard]] virtual IoFault fault() const noexcept { return {}; }
  /// Optional seed for drivers with randomness (the simulator). Returns false if unsupported.
  virtual bool set_seed(std::uint64_t /*seed*/) { return false; }
  /// Drivers with a pin map (`machine.io.pins`, e.g. modbus): takes the entries before
  /// configure() and returns their problems. Non-RT, load time. The default has no pin map.
  [[nodiscard]] virtual bool has_pin_map() const noexcept { return false; }
  virtual std::vector<PinMapError> set_pin_map(const std::vector<PinMapEntry>& /*entries*/) {
    return {};
  }
  /// Called by Runtime::run() before the first cycle and after the last (tasks joined): a driver
  /// with a non-RT thread of its own (a field bus) starts and stops it here, never at build time
  /// (`--check`, `--list-vars` build without running). Non-RT.
  virtual void start() {}
  virtual void stop() noexcept {}
  /// True for a driver that exchanges with real devices in wall time (a field bus): its image
  /// ages in wall time, so the virtual clock may run it only paced at 1x or slower (edmplc
  /// refuses anything faster). The simulator and loopback: false.
  [[nodiscard]] virtual bool wall_time_io() const noexcept { return false; }

  BlockStatus update(const CycleContext& /*ctx*/) noexcept final { return BlockStatus::kOk; }
};

}  // namespace edm::rt
