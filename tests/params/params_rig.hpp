#pragma once
// A machine holding one instance of every registered block and PROGRAM type (program `every`,
// each block named after its type) on the simulator, so that a test can reach every parameter a
// runtime writer can, through the runtime's variable registry.

#include <memory>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/modbus/driver.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "support/test_machine.hpp"

namespace edm::test {

struct EveryRegistry {
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
  EveryRegistry() {
    blocks::register_builtin_blocks(blocks);
    programs::register_builtin_programs(blocks);
    rt::register_runtime_drivers(drivers);
    sim::register_sim_driver(drivers);
    modbus::register_modbus_driver(drivers);
  }
};

inline const EveryRegistry& every_registry() {
  static const EveryRegistry r;
  return r;
}

inline std::unique_ptr<rt::Runtime> build_with_every_registry(const std::string& yaml,
                                                              const std::string& path) {
  const rt::Config cfg = rt::parse_config_text(yaml, path);
  return rt::Runtime::build(cfg, every_registry().blocks, every_registry().drivers);
}

/// The config of the machine with every type (default parameters, nothing wired).
inline std::string every_type_config() {
  std::string yaml =
      test_machine("every-type", "{driver: sim, task: t, params: {preset: drill, seed: 1}}") +
      R"(tasks:
  - {name: t, interval: 1ms, priority: 0, programs: [every]}
programs:
  - name: every
    blocks:
)";
  for (const std::string& type : every_registry().blocks.names()) {
    yaml += "      - {name: " + type + ", type: " + type + "}\n";
  }
  return yaml;
}

inline std::unique_ptr<rt::Runtime> build_every_type() {
  return build_with_every_registry(every_type_config(), "every-type.yaml");
}

}  // namespace edm::test
