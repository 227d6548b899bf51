// edmhmi check [--machine CONFIG] [--offsets FILE] PART.nc — offline interpretation
// (docs/gcode.md): against the config's conditions and soft limits, in the work frames of FILE
// (the JSON `edmhmi offset --json` prints) or all zero, starting at machine zero.
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/machining/bounded_read.hpp"
#include "edm/machining/machine_config.hpp"

namespace edmhmi {

int cmd_check(const CheckArgs& args) {
  const std::string& machine = args.machine;
  const std::string& part = args.part;
  edm::machining::MachineTables tables;
  try {
    tables = edm::machining::read_machine_tables(machine);
  } catch (const edm::machining::MachineConfigError& e) {
    for (const std::string& m : e.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  // Bounded, regular files only: /dev/zero, a FIFO or a directory is a located error, exit 2.
  const edm::machining::BoundedRead file =
      edm::machining::read_bounded_file(part, edm::machining::kMaxPartProgramBytes, "part program");
  if (!file.ok()) {
    std::fprintf(stderr, "%s\n", file.error.c_str());
    return kExitBadInput;
  }
  edm::hmi::GcodeOptions options;
  if (!args.offsets.empty()) {
    const edm::machining::BoundedRead json =
        edm::machining::read_bounded_file(args.offsets, 1u << 20, "offsets file");
    if (!json.ok()) {
      std::fprintf(stderr, "%s\n", json.error.c_str());
      return kExitBadInput;
    }
    std::string error;
    const edm::bridge::Json j = edm::bridge::Json::parse(json.text, nullptr, false);
    if (j.is_discarded()) {
      error = "not JSON";
    } else {
      edm::hmi::offsets_from_json(j, options.offsets, error);
    }
    if (!error.empty()) {
      std::fprintf(stderr, "%s:1:1: %s\n", args.offsets.c_str(), error.c_str());
      return kExitBadInput;
    }
  }
  const edm::hmi::GcodeResult r = edm::hmi::interpret_gcode(file.text, part, tables, options);
  if (!r.ok()) {
    for (const std::string& m : r.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  if (tables.kind == edm::machining::MachineKind::kWire) {
    std::printf(
        "%s: ok: %zu blocks, %d cut blocks, %.3f mm of cut path (machine %s, work offsets %s)\n",
        part.c_str(), r.blocks.size(), r.cut_blocks, r.cut_length_mm, machine.c_str(),
        args.offsets.empty() ? "zero" : args.offsets.c_str());
    return kExitOk;
  }
  std::printf(
      "%s: ok: %zu blocks, %d drilling blocks, %.3f mm drilled, estimated electrode wear %.3f mm "
      "(machine %s, work offsets %s)\n",
      part.c_str(), r.blocks.size(), r.drill_blocks, r.drill_depth_mm, r.electrode_wear_mm,
      machine.c_str(), args.offsets.empty() ? "zero" : args.offsets.c_str());
  return kExitOk;
}

}  // namespace edmhmi
