#pragma once
// The block and driver registries a simulated machine of tests/sim is built with: the built-in
// blocks and the "sim" driver, made once per test executable.

#include <utility>

#include "edm/blocks/register.hpp"
#include "edm/runtime/type_registry.hpp"
#include "edm/sim/sim_driver.hpp"

namespace edm::sim::test {

inline const std::pair<rt::BlockRegistry, rt::DriverRegistry>& sim_registries() {
  static const auto regs = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    blocks::register_builtin_blocks(r.first);
    register_sim_driver(r.second);
    return r;
  }();
  return regs;
}

}  // namespace edm::sim::test
