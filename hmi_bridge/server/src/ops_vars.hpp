#pragma once
// The variable and trace ops (docs/protocol.md "Variables", "Trace streaming"):
//   var.list, var.read, var.write, var.force, var.unforce → rt::VariableRegistry (non-RT API)
//   trace.start, trace.stop                               → the session's trace variables
// Server thread only.

#include <optional>
#include <string>

#include "ops_body.hpp"

namespace edm::bridge {

class Session;

namespace ops {

/// The body of a variable or trace op, or nullopt when `op` is not one of them.
std::optional<Body> dispatch_vars(Session& s, const std::string& op, const Json& msg);

}  // namespace ops
}  // namespace edm::bridge
