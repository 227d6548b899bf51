#pragma once
// Builds a Runtime for the programs' simulator tests: every built-in block and program type, the
// runtime's drivers and the simulator driver (registries built once, shared by all tests).

#include <memory>
#include <utility>

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"

namespace edm::test {

inline std::unique_ptr<rt::Runtime> build_sim_machine(const rt::Config& cfg,
                                                      const rt::BuildOptions& options = {}) {
  static const auto registries = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    blocks::register_builtin_blocks(r.first);
    programs::register_builtin_programs(r.first);
    rt::register_runtime_drivers(r.second);
    sim::register_sim_driver(r.second);
    return r;
  }();
  return rt::Runtime::build(cfg, registries.first, registries.second, options);
}

}  // namespace edm::test
