// fuzz_config: any bytes as a config file for the runtime's loader and validator: parsed
// (parse_config_text) and, when that passes, built (Runtime::build: block types, parameters,
// wires, driver, trace, retain) as `edmplc --check` does. Nothing is started. A ConfigError with
// located diagnostics is the normal outcome of a bad file; any other exception is a bug.

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "fuzz/fuzz_entry.hpp"

namespace edm::fuzz {
namespace {

constexpr const char* kPath = "fuzz.yaml";

struct Registries {
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
  std::string retain_file;  // every retain store of the fuzzer writes here, never where the
                            // input says (building a store and dropping it flushes it)
  Registries() {
    spdlog::set_level(spdlog::level::off);  // warnings of accepted configs are not findings
    blocks::register_builtin_blocks(blocks);
    programs::register_builtin_programs(blocks);
    rt::register_runtime_drivers(drivers);
    sim::register_sim_driver(drivers);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("edm-fuzz-config." + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    retain_file = (dir / "retain.txt").string();
  }
  ~Registries() {
    std::error_code ec;
    std::filesystem::remove_all(std::filesystem::path(retain_file).parent_path(), ec);
  }
  Registries(const Registries&) = delete;
  Registries& operator=(const Registries&) = delete;
};

Registries& registries() {
  static Registries r;
  return r;
}

void check_rejection(const rt::ConfigError& e) {
  EDM_FUZZ_CHECK(!e.diagnostics().empty());
  for (const rt::Diagnostic& d : e.diagnostics()) {
    // In the input itself, or in a fragment it includes (which then says where from).
    EDM_FUZZ_CHECK(d.loc.file == kPath || d.message.find("(included from ") != std::string::npos);
    EDM_FUZZ_CHECK(d.loc.line >= 1 && d.loc.col >= 1);
    EDM_FUZZ_CHECK(!d.message.empty());
  }
}

}  // namespace

int config_one_input(const std::uint8_t* data, std::size_t size) {
  Registries& reg = registries();
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    rt::Config cfg = rt::parse_config_text(text, kPath);
    if (!cfg.retain.file.empty()) {
      cfg.retain.file = reg.retain_file;
    }
    rt::BuildOptions options;
    options.load_retain = false;
    const std::unique_ptr<rt::Runtime> runtime =
        rt::Runtime::build(cfg, reg.blocks, reg.drivers, options);
    EDM_FUZZ_CHECK(runtime != nullptr);
  } catch (const rt::ConfigError& e) {
    check_rejection(e);
  }
  // Any other exception escapes: libFuzzer reports it as a crash (uncaught exception).
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::config_one_input)
