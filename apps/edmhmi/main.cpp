// edmhmi — the HMI process's command line (DESIGN §4). Implemented: `check`, which interprets a
// part program offline against a machine's conditions and soft limits (docs/gcode.md). The bridge
// subcommands (run, status, watch, ...) come with the bridge client (issue 5).
// Exit codes: 0 ok, 1 runtime failure (and subcommands not yet available), 2 bad input.

#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/machining/machine_tables.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;
constexpr std::size_t kMaxPartBytes = 64u << 20;  // a part program larger than this is refused

constexpr const char* kUsage =
    "usage: edmhmi [--host H] [--port P] [--token-file F] COMMAND ...\n"
    "commands:\n"
    "  check [--machine CONFIG] PART.nc  interpret PART.nc offline against CONFIG's conditions\n"
    "                                    and soft limits (default "
    "config/machines/drill-sim.yaml);\n"
    "                                    errors as PART.nc:line:col: message, exit 2\n"
    "  run PART.nc | status | watch VAR... | trace VAR... --out FILE.csv | stats | hold |\n"
    "  resume | stop | estop | reset     talk to edmplc over the bridge (not yet available)\n";

int usage(const std::string& message) {
  std::fprintf(stderr, "edmhmi: %s\n%s", message.c_str(), kUsage);
  return kExitBadInput;
}

bool is_bridge_command(std::string_view c) {
  for (std::string_view k :
       {"run", "status", "watch", "trace", "stats", "hold", "resume", "stop", "estop", "reset"}) {
    if (c == k) return true;
  }
  return false;
}

int check(const std::vector<std::string_view>& args) {
  std::string machine = EDM_DEFAULT_MACHINE;
  std::string part;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--machine") {
      if (i + 1 >= args.size()) return usage("--machine needs a config file");
      machine = std::string(args[++i]);
    } else if (args[i].starts_with("--")) {
      return usage("check: unknown option '" + std::string(args[i]) + "'");
    } else if (part.empty()) {
      part = std::string(args[i]);
    } else {
      return usage("check takes one part program");
    }
  }
  if (part.empty()) return usage("check needs a part program (PART.nc)");

  edm::machining::MachineTables tables;
  try {
    tables = edm::machining::read_machine_tables(machine);
  } catch (const edm::machining::MachineConfigError& e) {
    for (const std::string& m : e.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  std::ifstream in(part, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "%s: cannot open the part program\n", part.c_str());
    return kExitBadInput;
  }
  std::string text;
  text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad() || text.size() > kMaxPartBytes) {
    std::fprintf(stderr, "%s: unreadable or larger than %zu bytes\n", part.c_str(), kMaxPartBytes);
    return kExitBadInput;
  }
  const edm::hmi::GcodeResult r = edm::hmi::interpret_gcode(text, part, tables);
  if (!r.ok()) {
    for (const std::string& m : r.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  std::printf(
      "%s: ok: %zu blocks, %d drilling blocks, %.3f mm drilled, estimated electrode wear %.3f mm "
      "(machine %s)\n",
      part.c_str(), r.blocks.size(), r.drill_blocks, r.drill_depth_mm, r.electrode_wear_mm,
      machine.c_str());
  return kExitOk;
}

int run(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  std::size_t i = 0;
  // Bridge connection options; kept for the bridge subcommands.
  while (i < args.size() && args[i].starts_with("--")) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    }
    if (args[i] != "--host" && args[i] != "--port" && args[i] != "--token-file") {
      return usage("unknown option '" + std::string(args[i]) + "'");
    }
    if (i + 1 >= args.size()) return usage(std::string(args[i]) + " needs a value");
    i += 2;
  }
  if (i >= args.size()) return usage("missing command");
  const std::string_view command = args[i];
  const std::vector<std::string_view> rest(args.begin() + static_cast<std::ptrdiff_t>(i) + 1,
                                           args.end());
  if (command == "check") return check(rest);
  if (is_bridge_command(command)) {
    std::fprintf(stderr, "edmhmi: %s: not yet available (issue 5: bridge client)\n",
                 std::string(command).c_str());
    return kExitFailure;
  }
  return usage("unknown command '" + std::string(command) + "'");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return kExitFailure;
  }
}
