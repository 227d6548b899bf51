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

#include "edm/apps/cli.hpp"
#include "edm/sim/plant.hpp"

namespace {

using edm::apps::kExitBadInput;
using edm::apps::kExitOk;

constexpr const char* kUsage =
    "edm-wiremap [--thickness-mm H] [--seed N] [--open-voltage-v U] [--settle-s S]\n"
    "                   [--measure-s M]";

constexpr double kArcOffUs[] = {9, 12, 15, 20, 30, 40, 50};
constexpr double kServoRefV[] = {30, 35, 40, 45, 50, 60, 70};

int bad(const std::string& msg) {
  std::fprintf(stderr, "edm-wiremap: %s\nusage: %s\n", msg.c_str(), kUsage);
  return kExitBadInput;
}

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
  CLI::App app(
      "edm-wiremap: the wire plant's static map, steady Rab and cut speed over arc-off "
      "time x servo reference voltage (docs/simulator.md)",
      "edm-wiremap");
  app.add_option("--thickness-mm", thickness, "part thickness H [mm] (seed 000's case 1)")
      ->check(edm::apps::kFinite)
      ->capture_default_str();
  app.add_option("--seed", seed, "simulator seed")
      ->check(edm::apps::kFinite)
      ->capture_default_str();
  app.add_option("--open-voltage-v", open_v, "ignition voltage [V] (seed 000's machine)")
      ->check(edm::apps::kFinite)
      ->capture_default_str();
  app.add_option("--settle-s", settle_s, "time before measuring [s] (the kerf debris settles)")
      ->check(edm::apps::kFinite)
      ->capture_default_str();
  app.add_option("--measure-s", measure_s, "time measured [s]")
      ->check(edm::apps::kFinite)
      ->capture_default_str();
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) return *code;
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
