// The simulated machine's own gap-voltage servo (PLANT-MODEL.md §3, ε = k·(U_av − COMP)) driven by
// the servo reference voltage pin io.servo_ref_v, which seed 000's SelfTuningFuzzyPI and seed
// 001's SelfTuningRegulator act on; and the wire preset's arc-off time inside seed 000's actuator
// range (Table 1: 9…50 µs).

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/task.hpp"
#include "edm/sim/params.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_registries.hpp"
#include "support/files.hpp"

namespace edm::sim {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<rt::Runtime> build(const std::string& preset, double servo_ref_v) {
  const auto& regs = test::sim_registries();
  const std::string yaml = edm::test::test_data(
      "sim/servo_ref.yaml", {{"preset", preset}, {"servo_ref_v", std::to_string(servo_ref_v)}});
  auto r = rt::Runtime::build(rt::parse_config_text(yaml, "servo.yaml"), regs.first, regs.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  return r;
}

struct Settled {
  double depth_mm{0.0};
  double speed_mm_s{0.0};  // cut speed over the last 100 ms
  double u_av_v{0.0};      // mean gap voltage over the last 100 ms
  double gap_um{0.0};      // mean true front gap over the last 100 ms
};

Settled run(const std::string& preset, double servo_ref_v, int cycles) {
  auto r = build(preset, servo_ref_v);
  rt::VirtualClock clock;
  auto& task = *r->tasks()[0];
  double depth_before = 0.0;
  for (int k = 0; k < cycles; ++k) {
    const rt::TimePoint release{1ms * k};
    clock.advance_to(release);
    task.run_cycle(release, clock);
    if (k == cycles - 101) {
      depth_before = r->variables().read("io.depth_mm").value();
    }
  }
  Settled s;
  s.depth_mm = r->variables().read("io.depth_mm").value();
  s.speed_mm_s = (s.depth_mm - depth_before) / 0.1;
  s.u_av_v = r->variables().read("p.u.out").value();
  s.gap_um = r->variables().read("p.g.out").value();
  return s;
}

TEST(SimServoReference, the_wire_machine_feeds_on_its_servo_reference_voltage) {
  // vz_cmd stays 0: only the machine's servo can close the 100 µm start gap and cut. It is a
  // P servo, vz = −k·(U_av − Us), so while it follows the front at the cut speed v it runs with
  // the offset U_av − Us = v/k (k = servo_gain_mm_s_per_v of the wire preset).
  const Settled s = run("wire", 40.0, 10000);
  const double k = SimParams::preset("wire")->servo_gain_mm_s_per_v;
  EXPECT_GT(s.depth_mm, 0.5) << "the servo fed the wire into the work";
  EXPECT_GT(s.speed_mm_s, 0.0);
  EXPECT_NEAR(s.u_av_v, 40.0 + s.speed_mm_s / k, 2.0)
      << "gap " << s.gap_um << " um, speed " << s.speed_mm_s << " mm/s";
  EXPECT_LT(s.gap_um, 25.0) << "inside the sparking range of the quadratic Td law";
}

TEST(SimServoReference, a_higher_servo_reference_voltage_keeps_a_wider_gap) {
  // Raising the servo reference voltage lowers the abnormal ratio by widening the gap (seed 000
  // Fig. 3; seed 001: Us too large → open).
  const Settled low = run("wire", 30.0, 10000);
  const Settled high = run("wire", 50.0, 10000);
  EXPECT_GT(high.gap_um, low.gap_um + 0.5);
  EXPECT_GT(high.u_av_v, low.u_av_v + 10.0);
}

TEST(SimServoReference, the_sink_machine_follows_its_servo_reference_voltage_too) {
  const Settled s = run("sink", 60.0, 3000);
  EXPECT_NEAR(s.u_av_v, 60.0, 6.0);
}

TEST(SimServoReference, the_drill_preset_has_no_machine_servo) {
  // drill-sim.yaml wires its condition's servo_ref_v to the pin; the drill's feed is the runtime's
  // Td controller alone (seed 004), so k = 0 there and the pin moves nothing.
  EXPECT_EQ(SimParams::preset("drill")->servo_gain_mm_s_per_v, 0.0);
  const Settled s = run("drill", 40.0, 500);
  EXPECT_EQ(s.depth_mm, 0.0);
  EXPECT_NEAR(s.gap_um, 100.0, 0.5) << "the start gap";
}

TEST(SimServoReference, wire_arc_off_time_default_lies_in_seed_000_actuator_range) {
  const auto wire = *SimParams::preset("wire");
  EXPECT_GE(wire.default_arc_off_time_us, 9.0);
  EXPECT_LE(wire.default_arc_off_time_us, 50.0);
}

}  // namespace
}  // namespace edm::sim
