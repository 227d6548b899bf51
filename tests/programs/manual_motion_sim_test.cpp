// The operator's manual motion on the simulated drill machine (issue 21): reference (homing) to
// switches at positions the machine finds itself, jog by distance and by velocity with the
// dead-man, and touch-off by electrical contact — asserted against the simulator's truth (true
// machine positions, the work's surface, edges and bore), never against the block's own numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "operator_rig.hpp"

namespace edm::test {
namespace {

using rt::ManualError;
using rt::ManualOp;
using rt::TouchTarget;
using namespace std::chrono_literals;

// The work where the program does not know it: surface, datum (the block's corner) and size.
constexpr double kSurfaceZ = -7.345;
constexpr double kOriginX = 12.345, kOriginY = -6.789;
const std::string kWork =
    "work_surface_z_mm: -7.345, work_origin_x_mm: 12.345, work_origin_y_mm: -6.789, "
    "work_x_min_mm: 0, work_x_max_mm: 40, work_y_min_mm: 0, work_y_max_mm: 30, "
    "work_bore_x_mm: 30, work_bore_y_mm: 20, work_bore_d_mm: 6, "
    "start_x_mm: 20, start_y_mm: 10, start_gap_um: 3000";

TEST(ManualMotion, HomingFindsTheSwitchesAndSetsMachineCoordinates) {
  // Incremental encoders: at power-on they read the machine position less an unknown offset.
  OperatorRig m(kWork +
                    ", encoder_offset_x_mm: 23.4, encoder_offset_y_mm: -11.2, "
                    "encoder_offset_z_mm: 3.3",
                "referenced_at_start: false, reference_required: true");
  EXPECT_EQ(m.manual().referenced(), 0);
  EXPECT_FALSE(m.manual().may_run_programs());
  EXPECT_NEAR(m.read("io.x_mm"), m.truth().machine_x_mm - 23.4, 1e-3);

  const rt::ManualResult r = m.home();
  ASSERT_TRUE(r.ok) << rt::to_string(r.error);
  EXPECT_EQ(m.manual().referenced(), 0x7);
  EXPECT_TRUE(m.manual().may_run_programs());
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);  // no alarm on the way
  // Now the readings are machine coordinates: within the switch's repeatability (0.5 µm SD),
  // the latch speed's one cycle (0.2 µm) and the encoder's 1 µm quantum.
  m.run_for(20ms);
  EXPECT_NEAR(m.read("io.x_mm"), m.truth().machine_x_mm, 0.004);
  EXPECT_NEAR(m.read("io.y_mm"), m.truth().machine_y_mm, 0.004);
  EXPECT_NEAR(m.read("io.z_mm"), m.truth().machine_z_mm, 0.004);
  // The axes stand at their switches (90, 90, 15 in this machine).
  EXPECT_NEAR(m.truth().machine_x_mm, 90.0, 0.05);
  EXPECT_NEAR(m.truth().machine_z_mm, 15.0, 0.05);
}

TEST(ManualMotion, HomingRepeatsWithinTheSwitchRepeatability) {
  OperatorRig m(kWork, "");
  std::vector<double> err;
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(m.home(0x1).ok);  // X only
    m.run_for(10ms);
    err.push_back(m.read("io.x_mm") - m.truth().machine_x_mm);
    ASSERT_TRUE(m.jog(0, -5.0).ok);  // off the switch, then home again
  }
  double mean = 0.0, sd = 0.0;
  for (double e : err) mean += e / static_cast<double>(err.size());
  for (double e : err) sd += (e - mean) * (e - mean) / static_cast<double>(err.size() - 1);
  sd = std::sqrt(sd);
  std::printf("homing X, 10 times: reading - truth = %.2f +- %.2f um\n", mean * 1e3, sd * 1e3);
  EXPECT_LT(std::abs(mean), 0.003);
  EXPECT_LT(sd, 0.003);
}

TEST(ManualMotion, HomingWithoutASwitchInReachFailsSafely) {
  OperatorRig m(kWork, "home_search_max_mm: 5");  // the Z switch is 10 mm above: out of reach
  const rt::ManualResult r = m.home(0x4);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, ManualError::kNoSwitch);
  EXPECT_EQ(m.manual().referenced(), 0x7);  // absolute encoders: still referenced
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);
}

TEST(ManualMotion, IncrementalJogMovesExactlyTheDistanceAndRespectsSoftLimits) {
  OperatorRig m(kWork, "");
  for (double d : {0.001, 0.5, -2.25, 10.0}) {
    const double x0 = m.truth().machine_x_mm;
    const rt::ManualResult r = m.jog(0, d);
    ASSERT_TRUE(r.ok) << d;
    m.run_for(50ms);
    EXPECT_NEAR(m.truth().machine_x_mm - x0, d, 0.0015) << d;  // the encoder's quantum
  }
  // Out of range: refused before anything moves.
  const double x0 = m.truth().machine_x_mm;
  EXPECT_EQ(m.jog(0, 10.5).error, ManualError::kBadRequest);
  EXPECT_EQ(m.jog(0, 0.0005).error, ManualError::kBadRequest);
  // Beyond the soft limit (X max 100): from x = 28.25, +10 seven times reaches 98.25, the next
  // +10 is refused and nothing moves.
  for (int i = 0; i < 7; ++i) ASSERT_TRUE(m.jog(0, 10.0).ok);
  const double before = m.truth().machine_x_mm;
  const rt::ManualResult r = m.jog(0, 10.0);
  EXPECT_EQ(r.error, ManualError::kSoftLimit);
  m.run_for(50ms);
  EXPECT_NEAR(m.truth().machine_x_mm, before, 0.002);  // settles on its reference, no move
  EXPECT_GT(before, x0);
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);
}

TEST(ManualMotion, ContinuousJogStopsWhenTheClientStopsRefreshing) {
  OperatorRig m(kWork, "deadman: 300ms");
  rt::ManualRequest r;
  r.op = ManualOp::kJogVelocity;
  r.axis = 1;
  r.value = -2.0;
  // The client refreshes every 100 ms for 1 s, then dies.
  for (int i = 0; i < 10; ++i) {
    m.manual().request(r);
    m.run_for(100ms);
  }
  EXPECT_TRUE(m.manual().status().busy);
  const rt::TimePoint last_refresh = m.now - 100ms;  // seen by the 1 ms task within a cycle
  const double y_moving = m.truth().machine_y_mm;
  // Cycle by cycle: when does the axis stop moving (below 1 % of the jog speed)?
  double y = m.truth().machine_y_mm;
  rt::TimePoint stopped{};
  for (int k = 0; k < 2000 && stopped == rt::TimePoint{}; ++k) {
    m.run_for(1ms);
    const double y_now = m.truth().machine_y_mm;
    if (std::abs(y_now - y) < 0.02 * 2.0 * 1e-3) stopped = m.now;
    y = y_now;
  }
  ASSERT_NE(stopped, rt::TimePoint{}) << "the axis never stopped";
  const double after_ms = rt::to_seconds(stopped - last_refresh) * 1e3;
  std::printf("dead-man 300 ms: the axis stood still %.0f ms after the last refresh\n", after_ms);
  // Dead-man time + the deceleration from 2 mm/s at 200 mm/s² (10 ms) + the loop's settling.
  EXPECT_LE(after_ms, 300.0 + 10.0 + 40.0);
  EXPECT_GE(after_ms, 300.0);
  m.run_for(600ms);
  EXPECT_FALSE(m.manual().status().busy);
  EXPECT_EQ(m.manual().status().result.error, ManualError::kDeadman);
  EXPECT_LT(m.truth().machine_y_mm, y_moving);
}

TEST(ManualMotion, EstopEndsAJogAndStopsTheAxis) {
  OperatorRig m(kWork, "");
  rt::ManualRequest r;
  r.op = ManualOp::kJogVelocity;
  r.axis = 0;
  r.value = 4.0;
  m.manual().request(r);
  m.run_for(200ms);
  ASSERT_TRUE(m.manual().status().busy);
  const double x_at_estop = m.truth().machine_x_mm;
  m.runtime->machine().command(rt::MachineCommand::kEstop);
  m.run_for(60ms);  // the mechanics settle within ≈ 40 ms (the simulator's axis)
  const double x = m.truth().machine_x_mm;
  EXPECT_LT(std::abs(x - x_at_estop), 0.02);  // stopped from 4 mm/s within 20 µm
  m.run_for(200ms);
  EXPECT_NEAR(m.truth().machine_x_mm, x, 1e-3);
  EXPECT_FALSE(m.manual().status().busy);
  EXPECT_EQ(m.manual().status().result.error, ManualError::kInterrupted);
  // And a request while not READY is answered, never queued for later.
  m.manual().request(r);
  m.run_for(10ms);
  EXPECT_FALSE(m.manual().status().busy);
  EXPECT_NEAR(m.truth().machine_x_mm, x, 1e-3);
}

TEST(ManualMotion, TouchZFindsTheUnknownSurface) {
  OperatorRig m(kWork, "");
  const rt::ManualResult r = m.touch(TouchTarget::kZ);
  ASSERT_TRUE(r.ok) << rt::to_string(r.error);
  // Contact at the sensing threshold (1 µm, noise 0.3 µm) above the surface.
  EXPECT_NEAR(r.z, kSurfaceZ, 0.003);
  // Backed off and back at the start: not in contact, above the surface, generator never on.
  m.run_for(10ms);
  EXPECT_FALSE(m.read("io.contact") != 0.0);
  EXPECT_GT(m.truth().machine_z_mm, kSurfaceZ + 1.0);
  EXPECT_EQ(m.truth().pulses, 0U);
  EXPECT_NEAR(m.truth().depth_mm, 0.0, 1e-12);  // nothing eroded
}

TEST(ManualMotion, TouchRepeatabilityOverTwentyTouches) {
  OperatorRig m(kWork, "");
  std::vector<double> z;
  for (int i = 0; i < 20; ++i) {
    const rt::ManualResult r = m.touch(TouchTarget::kZ);
    ASSERT_TRUE(r.ok);
    z.push_back(r.z - kSurfaceZ);
  }
  double mean = 0.0, sd = 0.0;
  for (double e : z) mean += e / 20.0;
  for (double e : z) sd += (e - mean) * (e - mean) / 19.0;
  sd = std::sqrt(sd);
  std::printf("touch z, 20 touches: found - true surface = %.2f +- %.2f um\n", mean * 1e3,
              sd * 1e3);
  EXPECT_LT(std::abs(mean), 0.003);
  EXPECT_LT(sd, 0.0015);
}

TEST(ManualMotion, TouchEdgesFromOutsideAndTheBoreCentreFromInside) {
  OperatorRig m(kWork, "");
  // Beside the block's X− face (x = 12.345), 1 mm below the surface.
  ASSERT_TRUE(m.jog(0, -10.0).ok);  // x 20 → 10 (the electrode's edge at 10.5)
  ASSERT_TRUE(m.jog(2, -4.0).ok);   // z from 3 mm above to 1 mm below the surface
  rt::ManualResult r = m.touch(TouchTarget::kXPlus);
  ASSERT_TRUE(r.ok) << rt::to_string(r.error);
  EXPECT_NEAR(r.x, kOriginX, 0.003);
  // The Y− face (y = −6.789) from below it.
  ASSERT_TRUE(m.jog(2, 4.0).ok);
  ASSERT_TRUE(m.jog(0, 10.0).ok);   // x back to 20
  ASSERT_TRUE(m.jog(1, -10.0).ok);  // y 10 → 0
  ASSERT_TRUE(m.jog(1, -9.0).ok);   // → −9
  ASSERT_TRUE(m.jog(2, -4.0).ok);
  r = m.touch(TouchTarget::kYPlus);
  ASSERT_TRUE(r.ok) << rt::to_string(r.error);
  EXPECT_NEAR(r.y, kOriginY, 0.003);
  // Inside the bore (centre at datum + (30, 20), Ø6), off its centre by (0.7, −1.1).
  ASSERT_TRUE(m.jog(2, 4.0).ok);
  const double bx = kOriginX + 30.0, by = kOriginY + 20.0;
  for (double dx = bx + 0.7 - m.read("io.x_mm"); std::abs(dx) > 1e-9;) {
    const double step = std::clamp(dx, -10.0, 10.0);
    ASSERT_TRUE(m.jog(0, step).ok);
    dx -= step;
  }
  for (double dy = by - 1.1 - m.read("io.y_mm"); std::abs(dy) > 1e-9;) {
    const double step = std::clamp(dy, -10.0, 10.0);
    ASSERT_TRUE(m.jog(1, step).ok);
    dy -= step;
  }
  ASSERT_TRUE(m.jog(2, -4.0).ok);
  r = m.touch(TouchTarget::kCenter);
  ASSERT_TRUE(r.ok) << rt::to_string(r.error);
  EXPECT_NEAR(r.x, bx, 0.003);
  EXPECT_NEAR(r.y, by, 0.003);
  EXPECT_NEAR(r.size, 6.0, 0.005);
  std::printf("bore centre found at (%+.4f, %+.4f) mm of the truth, diameter %.4f mm\n", r.x - bx,
              r.y - by, r.size);
  m.run_for(20ms);
  EXPECT_NEAR(m.truth().machine_x_mm, bx, 0.003);  // it ends at the centre
  EXPECT_NEAR(m.truth().machine_y_mm, by, 0.003);
}

TEST(ManualMotion, TouchWithoutContactFailsAndReturnsToItsStart) {
  OperatorRig m(kWork, "touch_max_mm: 2");  // the surface is 3 mm below: out of reach
  const double z0 = m.truth().machine_z_mm;
  const rt::ManualResult r = m.touch(TouchTarget::kZ);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, ManualError::kNoContact);
  m.run_for(20ms);
  EXPECT_NEAR(m.truth().machine_z_mm, z0, 0.002);
}

TEST(ManualMotion, TouchRefusedWhenAlreadyInContact) {
  OperatorRig m(kWork, "");
  ASSERT_TRUE(m.jog(2, -3.0).ok);  // the tip onto the surface (3 mm above it at the start)
  m.run_for(10ms);
  const rt::ManualResult r = m.touch(TouchTarget::kZ);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, ManualError::kAlreadyInContact);
}

// Issue 32: every shipped drill machine has the job's manual wires (one shared wiring,
// config/machines/fragments/drill-job-wiring.yaml): it homes with incremental encoders and then
// touches off the unknown surface, against the simulator's truth. drill-fuzzy-sim could do
// neither before it included the wiring.
class DrillMachineManual : public ::testing::TestWithParam<const char*> {};

TEST_P(DrillMachineManual, HomesAndTouchesOffTheSurface) {
  OperatorRig m(kWork +
                    ", encoder_offset_x_mm: 23.4, encoder_offset_y_mm: -11.2, "
                    "encoder_offset_z_mm: 3.3",
                "referenced_at_start: false, reference_required: true", 1, GetParam());
  EXPECT_FALSE(m.manual().may_run_programs());
  const double x0 = m.truth().machine_x_mm, y0 = m.truth().machine_y_mm;
  const double z0 = m.truth().machine_z_mm;  // 3 mm above the surface
  const rt::ManualResult homed = m.home();
  ASSERT_TRUE(homed.ok) << rt::to_string(homed.error);
  EXPECT_EQ(m.manual().referenced(), 0x7);
  EXPECT_TRUE(m.manual().may_run_programs());
  m.run_for(20ms);
  EXPECT_NEAR(m.read("io.x_mm"), m.truth().machine_x_mm, 0.004);
  EXPECT_NEAR(m.read("io.y_mm"), m.truth().machine_y_mm, 0.004);
  EXPECT_NEAR(m.read("io.z_mm"), m.truth().machine_z_mm, 0.004);
  // Back over the work from the switches (the readings are machine coordinates now), then
  // touch: the surface it finds is the simulator's.
  const auto jog_to = [&m](int axis, const char* pin, double target) {  // 10 mm a jog at most
    for (int i = 0; i < 20 && std::abs(target - m.read(pin)) > 1e-3; ++i) {
      if (!m.jog(axis, std::clamp(target - m.read(pin), -10.0, 10.0)).ok) return false;
    }
    return std::abs(target - m.read(pin)) <= 1e-3;
  };
  ASSERT_TRUE(jog_to(0, "io.x_mm", x0));
  ASSERT_TRUE(jog_to(1, "io.y_mm", y0));
  ASSERT_TRUE(jog_to(2, "io.z_mm", z0));
  EXPECT_NEAR(m.truth().machine_z_mm, z0, 0.01);
  const rt::ManualResult touched = m.touch(TouchTarget::kZ);
  ASSERT_TRUE(touched.ok) << rt::to_string(touched.error);
  EXPECT_NEAR(touched.z, kSurfaceZ, 0.005);
  m.run_for(10ms);
  EXPECT_FALSE(m.read("io.contact") != 0.0);
  EXPECT_EQ(m.truth().pulses, 0U);  // the generator never on
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);
}

INSTANTIATE_TEST_SUITE_P(Shipped, DrillMachineManual,
                         ::testing::Values("drill-sim", "drill-fuzzy-sim"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           return std::string(p.param) == "drill-sim" ? "DrillSim"
                                                                      : "DrillFuzzySim";
                         });

}  // namespace
}  // namespace edm::test
