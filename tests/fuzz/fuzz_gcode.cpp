// fuzz_gcode: any bytes as a part program for the G-code interpreter (hmi/), checked against the
// drill-sim machine's tables. Bad programs are normal: the interpreter must return located errors
// and never crash, throw or hang. What it accepts must also be accepted by the runtime's
// whole-program check and survive the bridge's JSON codec unchanged, as an upload would.

#include <string>
#include <string_view>

#include "edm/bridge/codec.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/machining/program_check.hpp"
#include "fuzz/fuzz_entry.hpp"

namespace edm::fuzz {
namespace {

const machining::MachineTables& drill_sim_tables() {
  static const machining::MachineTables tables = machining::read_machine_tables(
      std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  return tables;
}

void check_errors(const hmi::GcodeResult& r, const hmi::GcodeOptions& options) {
  EDM_FUZZ_CHECK(r.blocks.empty());
  // At most max_errors, plus the one "too many errors" line.
  EDM_FUZZ_CHECK(r.errors.size() <= options.max_errors + 1);
  int prev_line = 0;
  for (const hmi::GcodeError& e : r.errors) {
    EDM_FUZZ_CHECK(e.line >= 1 && e.col >= 1);
    EDM_FUZZ_CHECK(!e.message.empty());
    EDM_FUZZ_CHECK(e.line >= prev_line);  // file order
    prev_line = e.line;
  }
}

void check_program(const hmi::GcodeResult& r, const hmi::GcodeOptions& options) {
  const machining::MachineTables& tables = drill_sim_tables();
  EDM_FUZZ_CHECK(machining::check_program(r.blocks, tables, options.start_mm).empty());
  for (const machining::MotionBlock& b : r.blocks) {
    machining::MotionBlock back;
    std::string error;
    EDM_FUZZ_CHECK(bridge::from_json(bridge::to_json(b), back, error));
    EDM_FUZZ_CHECK(back == b);
  }
}

}  // namespace

int gcode_one_input(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const hmi::GcodeOptions options;
  const hmi::GcodeResult r = hmi::interpret_gcode(text, "fuzz.nc", drill_sim_tables(), options);
  if (r.ok()) {
    check_program(r, options);
  } else {
    check_errors(r, options);
  }
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::gcode_one_input)
