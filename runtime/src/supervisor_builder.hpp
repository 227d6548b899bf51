#pragma once
// Private to the runtime builder: builds the safety supervisor from `machine.safety`, resolving
// its io.* names to the I/O driver's pins and checking their direction and type (file:line:col).
// Non-RT; thread-compatible.

#include <functional>
#include <memory>

#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/supervisor.hpp"

namespace edm::rt {

/// The pin an io.<pin> name stands for; an empty PinRef (pin == nullptr) after the resolver
/// reported why.
using IoPinResolver = std::function<PinRef(const NameRef&)>;

/// nullptr when the config has no `machine.safety` or a problem was reported to `diag`.
std::unique_ptr<Supervisor> build_supervisor(const SafetySpec& spec,
                                             const machining::MachineTables& tables,
                                             Machine& machine, const ManualControl* manual,
                                             Duration io_period, const IoPinResolver& resolve,
                                             DiagnosticSink& diag);

}  // namespace edm::rt
