#pragma once
// What an NCMD/DCMD metric may write (docs/mqtt.md "Commands"): nothing when commands are off;
// otherwise only a parameter listed in mqtt.commands.writable, with a value whose Sparkplug
// datatype matches the parameter's type and converts to it exactly (an Int64 of 2^63-1 is no
// LREAL, 2 is no BOOL, a Boolean is no number). The write then goes through the registry's
// write(), the entry point the bridge's var.write and the Modbus server use, which checks the
// parameter's physical range and the block's validate() on the shadow copy and queues it to the
// owning task.
// Non-RT (the publisher's thread). Thread-compatible; the registry is thread-safe.

#include <optional>
#include <string>
#include <vector>

#include "edm/runtime/param.hpp"
#include "edm/runtime/variables.hpp"
#include "edm/sparkplug/sparkplug.hpp"
#include "edm/telemetry/command_intake.hpp"

namespace edm::telemetry {

/// A metric's value as a value of parameter type `type`, exactly; nullopt with `why` when its
/// datatype or value does not fit (REAL and TIME take integers within ±2^53 only, TIME in
/// seconds; STRING nothing).
std::optional<rt::ParamValue> command_value(const sparkplug::Metric& m, rt::ParamType type,
                                            std::string& why);

class CommandGate {
 public:
  CommandGate(rt::VariableRegistry& vars, bool enabled, std::vector<std::string> writable)
      : vars_(vars), enabled_(enabled), writable_(std::move(writable)) {}

  /// Writes the metric's parameter or says why not (`why` quotes what came from the broker).
  CommandOutcome apply(const sparkplug::Metric& m, std::string& why);

 private:
  rt::VariableRegistry& vars_;
  bool enabled_;
  std::vector<std::string> writable_;
};

}  // namespace edm::telemetry
