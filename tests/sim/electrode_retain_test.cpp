// Issue 19 item 5 (the simulator's side): the electrode length left survives a restart through
// the runtime's retain store. `io.electrode_length_mm` reads the plant's length left (what the
// store saves) and a write of it — the store's restore at start — goes back into the plant.

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/task.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_registries.hpp"
#include "support/temp_dir.hpp"

namespace edm::sim {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<rt::Runtime> build(const std::string& retain_file) {
  const auto& regs = test::sim_registries();
  const std::string yaml = R"(version: 1
machine:
  name: retained-electrode
  io: {driver: sim, params: {preset: drill, seed: 1000, servo_gain_mm_s_per_v: 0.05}}
tasks:
  - {name: servo, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: g, type: Gain}
    wires:
      g.in: io.electrode_mm
      io.servo_ref_v: 40
      io.gen_arm: true
      io.gen_on: true
retain:
  file: )" + retain_file + R"(
  variables: [io.electrode_length_mm]
)";
  auto r = rt::Runtime::build(rt::parse_config_text(yaml, "m.yaml"), regs.first, regs.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  return r;
}

void run_cycles(rt::Runtime& r, int cycles) {
  rt::VirtualClock clock;
  auto& task = *r.tasks()[0];
  for (int k = 0; k < cycles; ++k) {
    const rt::TimePoint release{1ms * k};
    clock.advance_to(release);
    task.run_cycle(release, clock);
  }
}

Plant& plant_of(rt::Runtime& r) { return dynamic_cast<SimDriver&>(r.driver()).plant(); }

TEST(SimElectrodeRetain, the_length_left_is_read_back_and_a_write_restores_it_into_the_plant) {
  edm::test::TempDir dir("edm-sim-retain");
  double worn_mm = 0.0;
  {
    auto r = build(dir.file("retain.dat"));
    EXPECT_DOUBLE_EQ(r->variables().read("io.electrode_length_mm").value(), 300.0);
    run_cycles(*r, 3000);  // drills ≈ 1 mm and wears ≈ 0.8 mm of the tube
    worn_mm = plant_of(*r).state().electrode_length_mm;
    EXPECT_LT(worn_mm, 299.7);
    // The parameter reads the length left: that is what the store saves.
    EXPECT_DOUBLE_EQ(r->variables().read("io.electrode_length_mm").value(), worn_mm);
    ASSERT_NE(r->retain(), nullptr);
    EXPECT_TRUE(r->retain()->flush());
  }
  const rt::RetainLoadResult saved = rt::load_retain_file(dir.file("retain.dat"));
  ASSERT_EQ(saved.status, rt::RetainLoadStatus::kLoaded) << saved.warning;
  EXPECT_DOUBLE_EQ(saved.values.at("io.electrode_length_mm").r, worn_mm);

  // A restart: the machine continues with the length left, not a new 300 mm tube, and its tip
  // starts higher above the work by what was worn (the axis scale is the new tube's).
  auto r = build(dir.file("retain.dat"));
  const PlantState& st = plant_of(*r).state();
  EXPECT_DOUBLE_EQ(st.electrode_length_mm, worn_mm);
  EXPECT_NEAR(st.gap_um, plant_of(*r).params().start_gap_um + (300.0 - worn_mm) * 1e3, 1e-6);
  run_cycles(*r, 1);
  EXPECT_DOUBLE_EQ(r->variables().read("p.g.out").value(), worn_mm);
  run_cycles(*r, 1000);
  EXPECT_LT(r->variables().read("io.electrode_length_mm").value(), worn_mm);
}

TEST(SimElectrodeRetain, the_electrode_length_is_writable_at_run_time_and_load_time_ones_are_not) {
  edm::test::TempDir dir("edm-sim-retain");
  auto r = build(dir.file("retain.dat"));
  EXPECT_TRUE(r->variables().write("io.electrode_length_mm", 42.0, /*apply_now=*/true));
  EXPECT_DOUBLE_EQ(plant_of(*r).state().electrode_length_mm, 42.0);
  EXPECT_FALSE(r->variables().write("io.electrode_length_mm", -1.0, /*apply_now=*/true));
  const rt::VarStatus refused = r->variables().write("io.peak_current_a", 10.0, true);
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.message.find("load time only"), std::string::npos) << refused.message;
}

}  // namespace
}  // namespace edm::sim
