#include "edm/apps/offline_runtime.hpp"

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/sim/sim_driver.hpp"

namespace edm::apps {

namespace {

struct Registries {
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
};

const Registries& registries() {
  static const Registries r = [] {
    Registries out;
    blocks::register_builtin_blocks(out.blocks);
    programs::register_builtin_programs(out.blocks);
    rt::register_runtime_drivers(out.drivers);
    sim::register_sim_driver(out.drivers);
    return out;
  }();
  return r;
}

}  // namespace

const rt::BlockRegistry& builtin_blocks() { return registries().blocks; }

const rt::DriverRegistry& builtin_drivers() { return registries().drivers; }

std::unique_ptr<rt::Runtime> build_offline(const rt::Config& cfg) {
  rt::BuildOptions options;
  options.load_retain = false;
  return rt::Runtime::build(cfg, builtin_blocks(), builtin_drivers(), options);
}

}  // namespace edm::apps
