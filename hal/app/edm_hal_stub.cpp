// edm-hal-stub: a HAL userspace component with the pins it is told, and nothing else, for loading
// a hardware .hal file where the hardware is not (examples/hal/*-sim.hal, docs/hal.md): it stands
// in for a card's driver (hm2_eth's hm2_7i96s.0.*) or the parallel port's with the same pin names.
//   edm-hal-stub --name hm2_7i96s.0 stepgen.00.velocity-cmd:float:in
//   stepgen.00.position-fb:float:out
// A pin spec is NAME:TYPE:DIR (TYPE bit, float, s32, u32; DIR in or out, the card's own view).
// Ends on SIGTERM/SIGINT.
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/hal/component.hpp"

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int /*sig*/) { g_stop.store(true); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A HAL component with the given pins (a stand-in for hardware, docs/hal.md)",
               "edm-hal-stub"};
  std::string name;
  std::vector<std::string> specs;
  app.add_option("--name", name, "HAL component name; pins are <name>.<pin>")->required();
  app.add_option("pins", specs, "NAME:TYPE:DIR (bit|float|s32|u32, in|out)")->required();
  if (const auto code =
          edm::apps::parse(app, argc, argv, "edm-hal-stub --name N PIN:TYPE:DIR...")) {
    return *code;
  }
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  edm::hal::Component comp;
  if (const std::string e = comp.open(name); !e.empty()) {
    std::fprintf(stderr, "edm-hal-stub: %s\n", e.c_str());
    return 2;
  }
  for (const std::string& s : specs) {
    const auto c1 = s.find(':');
    const auto c2 = c1 == std::string::npos ? c1 : s.find(':', c1 + 1);
    if (c2 == std::string::npos) {
      std::fprintf(stderr, "edm-hal-stub: '%s' is not NAME:TYPE:DIR\n", s.c_str());
      return 2;
    }
    const std::string pin = s.substr(0, c1);
    const std::string type = s.substr(c1 + 1, c2 - c1 - 1);
    const std::string dir = s.substr(c2 + 1);
    edm::hal::HalType t{};
    if (type == "bit") {
      t = edm::hal::HalType::kBit;
    } else if (type == "float") {
      t = edm::hal::HalType::kFloat;
    } else if (type == "s32") {
      t = edm::hal::HalType::kS32;
    } else if (type == "u32") {
      t = edm::hal::HalType::kU32;
    } else {
      std::fprintf(stderr, "edm-hal-stub: '%s': unknown type '%s'\n", s.c_str(), type.c_str());
      return 2;
    }
    if (dir != "in" && dir != "out") {
      std::fprintf(stderr, "edm-hal-stub: '%s': direction must be in or out\n", s.c_str());
      return 2;
    }
    edm::hal::PinSlot slot;
    if (const std::string e = comp.add_pin(
            pin, t, dir == "in" ? edm::hal::HalDir::kIn : edm::hal::HalDir::kOut, slot);
        !e.empty()) {
      std::fprintf(stderr, "edm-hal-stub: %s\n", e.c_str());
      return 2;
    }
  }
  if (const std::string e = comp.ready(); !e.empty()) {
    std::fprintf(stderr, "edm-hal-stub: %s\n", e.c_str());
    return 2;
  }
  while (!g_stop.load()) {
    pause();  // nothing to do: the pins are the point
  }
  return 0;
}
