// edm-wiremap — the wire plant's static map: for each arc-off time (rows) and servo reference
// voltage (columns) of seed 000's actuator ranges (Table 1: 9…50 µs, 30…70 V), the simulator
// cuts a part of thickness H with the machine's own gap-voltage servo, and the steady Rab and
// cut speed after a settling time are printed as a Markdown table. Rupture is switched off, so
// every cell is measured over the same time. docs/simulator.md §10d.
// Exit codes: 0 ok, 2 bad arguments.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "cli_number.hpp"
#include "edm/sim/plant.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;

constexpr const char* kUsage =
    "usage: edm-wiremap [--thickness-mm H] [--seed N] [--open-voltage-v U] [--settle-s S]\n"
    "                   [--measure-s M]\n"
    "  --thickness-mm  part thickness H [mm] (default 50, seed 000's case 1)\n"
    "  --seed          simulator seed (default 1)\n"
    "  --open-voltage-v ignition voltage [V] (default 110, seed 000's machine)\n"
    "  --settle-s      time before measuring [s] (default 20: the kerf debris settles)\n"
    "  --measure-s     time measured [s] (default 20)\n";

constexpr double kArcOffUs[] = {9, 12, 15, 20, 30, 40, 50};
constexpr double kServoRefV[] = {30, 35, 40, 45, 50, 60, 70};

int bad(const std::string& msg) {
  std::fprintf(stderr, "edm-wiremap: %s\n%s", msg.c_str(), kUsage);
  return kExitBadInput;
}

using edm::apps::parse_number;

struct Cell {
  double rab{0.0};           // mean of the 40 ms Rab, sampled every 40 ms
  double speed_mm_min{0.0};  // cut length per minute over the measured time
};

Cell measure(const edm::sim::SimParams& params, std::uint64_t seed, double arc_off_us,
             double servo_ref_v, double settle_s, double measure_s) {
  edm::sim::Plant plant(params, seed);
  edm::sim::PlantCommands c;
  c.generator_armed = c.generator_on = true;
  c.arc_off_time_us = arc_off_us;
  c.servo_ref_v = servo_ref_v;
  plant.set_commands(c);
  const auto settle_ms = static_cast<std::int64_t>(std::llround(settle_s * 1e3));
  const auto end_ms = settle_ms + static_cast<std::int64_t>(std::llround(measure_s * 1e3));
  double rab_sum = 0.0, depth0 = 0.0;
  std::int64_t n = 0;
  for (std::int64_t ms = 1; ms <= end_ms; ++ms) {
    plant.advance_to(std::chrono::milliseconds(ms));
    (void)plant.take_sensors();
    if (ms == settle_ms) depth0 = plant.state().depth_mm;
    if (ms > settle_ms && ms % 40 == 0) {
      rab_sum += plant.state().rab;
      ++n;
    }
  }
  return {n > 0 ? rab_sum / static_cast<double>(n) : 0.0,
          (plant.state().depth_mm - depth0) / (measure_s / 60.0)};
}

}  // namespace

int main(int argc, char** argv) {
  double thickness = 50.0, open_v = 110.0, settle_s = 20.0, measure_s = 20.0, seed = 1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    }
    double* target = arg == "--thickness-mm"     ? &thickness
                     : arg == "--open-voltage-v" ? &open_v
                     : arg == "--settle-s"       ? &settle_s
                     : arg == "--measure-s"      ? &measure_s
                     : arg == "--seed"           ? &seed
                                                 : nullptr;
    if (target == nullptr) return bad("unknown option '" + std::string(arg) + "'");
    if (i + 1 >= argc) return bad(std::string(arg) + " needs a value");
    const auto v = parse_number(argv[++i]);
    if (!v) return bad(std::string(arg) + ": not a number: '" + argv[i] + "'");
    *target = *v;
  }
  if (!(thickness > 0.0)) return bad("--thickness-mm must be > 0");
  if (!(open_v > 0.0)) return bad("--open-voltage-v must be > 0");
  if (!(settle_s >= 0.0 && settle_s <= 3600.0)) return bad("--settle-s must be in [0, 3600]");
  if (!(measure_s >= 0.04 && measure_s <= 3600.0))
    return bad("--measure-s must be in [0.04, 3600]");
  if (!(seed >= 0.0 && seed == std::floor(seed) && seed < 9.0e15)) {
    return bad("--seed must be a whole number >= 0");
  }
  edm::sim::SimParams params = *edm::sim::SimParams::preset("wire");
  params.open_voltage_v = open_v;
  params.wire_thickness_profile = "0:" + std::to_string(thickness);
  params.wire_hole_from_mm = params.wire_hole_to_mm = 0.0;  // plain part
  params.wire_break_rab_ms = 1e15;                          // rupture off: every cell measured
  params.wire_ibk_ref_a = 1e9;
  if (const auto errs = params.validate(); !errs.empty()) {
    return bad(errs.front().field + ": " + errs.front().message);
  }
  std::printf(
      "Wire preset, H = %g mm, U0 = %g V, seed %.0f; mean Rab / cut speed mm/min over "
      "%g s after %g s.\n\n| arc-off µs \\ servo ref V |",
      thickness, open_v, seed, measure_s, settle_s);
  for (const double v : kServoRefV) std::printf(" %g |", v);
  std::printf("\n|---|");
  for (std::size_t j = 0; j < std::size(kServoRefV); ++j) std::printf("---|");
  std::printf("\n");
  for (const double u : kArcOffUs) {
    std::printf("| %g |", u);
    for (const double v : kServoRefV) {
      const Cell cell =
          measure(params, static_cast<std::uint64_t>(seed), u, v, settle_s, measure_s);
      std::printf(" %.2f / %.2f |", cell.rab, cell.speed_mm_min);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  return kExitOk;
}
