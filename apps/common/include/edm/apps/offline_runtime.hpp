#pragma once
// A Runtime with every type this build has, for the offline tools and bench drivers that run a
// shipped config on the virtual clock (edm-greyhorizon, the controller benchmark).
// Non-RT. builtin_*() are thread-safe (built once on first use, read-only afterwards);
// build_offline() may be called from several threads at once.

#include <memory>

#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::apps {

/// The built-in blocks and the C++ PROGRAM types.
const rt::BlockRegistry& builtin_blocks();
/// The runtime's drivers and the simulator ("sim").
const rt::DriverRegistry& builtin_drivers();

/// Builds `cfg` with the built-in types and without reading a retain file (a run starts from the
/// config alone). Throws what Runtime::build throws.
std::unique_ptr<rt::Runtime> build_offline(const rt::Config& cfg);

}  // namespace edm::apps
