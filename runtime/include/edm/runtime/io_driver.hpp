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

#include <string_view>

#include "edm/runtime/block.hpp"

namespace edm::rt {

/// A fault reported by a driver (code 0 = none). Text is static.
struct IoFault {
  int code{0};
  const char* text{""};
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

  BlockStatus update(const CycleContext& /*ctx*/) noexcept final { return BlockStatus::kOk; }
};

}  // namespace edm::rt
