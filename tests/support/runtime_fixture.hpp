#pragma once
// Builds a Runtime from YAML text with the built-in and test blocks, for runtime tests.

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "support/test_blocks.hpp"

namespace edm::test {

struct Registries {
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
  Registries() {
    blocks::register_builtin_blocks(blocks);
    register_test_blocks(blocks);
    rt::register_runtime_drivers(drivers);
  }
};

inline const Registries& registries() {
  static Registries r;
  return r;
}

inline std::unique_ptr<rt::Runtime> build_from_text(const std::string& yaml,
                                                    const std::string& path = "test.yaml") {
  rt::Config cfg = rt::parse_config_text(yaml, path);
  return rt::Runtime::build(cfg, registries().blocks, registries().drivers);
}

/// The first diagnostic of a config that must fail to build.
inline rt::Diagnostic build_error(const std::string& yaml) {
  try {
    build_from_text(yaml);
  } catch (const rt::ConfigError& e) {
    return e.diagnostics().front();
  }
  ADD_FAILURE() << "config was accepted:\n" << yaml;
  return {};
}

}  // namespace edm::test
