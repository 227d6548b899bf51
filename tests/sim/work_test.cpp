// Issue 21 "operator's day", the simulator's part (docs/simulator.md §3a): a work placed where the
// program does not know it, incremental encoders and "set actual position", reference switches,
// touch sensing at a sensing voltage, and a hole that survives a restart.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/task.hpp"
#include "edm/sim/plant.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_registries.hpp"
#include "support/temp_dir.hpp"

namespace edm::sim {
namespace {

using namespace std::chrono_literals;

bool has_error(const std::vector<rt::ParamError>& errs, std::string_view field) {
  for (const auto& e : errs) {
    if (e.field == field) return true;
  }
  return false;
}

/// Advances in steps of `step_us` under `c` until `done` holds (true) or `max_ms` pass (false).
bool run_until(Plant& p, const PlantCommands& c, double max_ms,
               const std::function<bool(const PlantState&)>& done, int step_us = 100) {
  p.set_commands(c);
  const auto end = p.state().now + std::chrono::microseconds(std::llround(max_ms * 1e3));
  while (p.state().now < end) {
    p.advance_to(p.state().now + std::chrono::microseconds(step_us));
    if (done(p.state())) return true;
  }
  return false;
}

void run_ms(Plant& p, const PlantCommands& c, double ms) {
  run_until(
      p, c, ms, [](const PlantState&) { return false; }, 1000);
}

PlantCommands velocity(double vx, double vy, double vz) {
  PlantCommands c;
  c.vx_mm_s = vx;
  c.vy_mm_s = vy;
  c.vz_mm_s = vz;
  return c;
}

PlantCommands touching(double vx, double vy, double vz) {
  PlantCommands c = velocity(vx, vy, vz);
  c.touch_mode = true;
  return c;
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// --- Where the work is ----------------------------------------------------------------------

struct DrillFigures {
  double depth_mm, removed_mm3, wear_mm3, z_mm, machine_z_mm;
  std::uint64_t pulses;
};

/// 2 s of drilling with the machine's own voltage servo (k = 0.05 mm/s/V, 40 V).
DrillFigures drill(const SimParams& params) {
  SimParams p = params;
  p.servo_gain_mm_s_per_v = 0.05;
  Plant plant(p, 1000);
  PlantCommands c;
  c.generator_armed = c.generator_on = true;
  c.servo_ref_v = 40.0;
  run_ms(plant, c, 2000);
  const PlantState& s = plant.state();
  return {s.depth_mm, s.removed_mm3, s.wear_mm3, s.z_mm, s.machine_z_mm, s.pulses};
}

TEST(SimWork, the_new_parameters_at_their_defaults_leave_drilling_as_it_was) {
  const DrillFigures before = drill(SimParams{});
  SimParams p;  // every new parameter written out at the value the issue gives as its default
  p.work_surface_z_mm = 0.0;
  p.work_origin_x_mm = p.work_origin_y_mm = 0.0;
  p.work_x_min_mm = p.work_y_min_mm = -50.0;
  p.work_x_max_mm = p.work_y_max_mm = 50.0;
  p.work_bore_x_mm = p.work_bore_y_mm = p.work_bore_d_mm = 0.0;
  p.start_x_mm = p.start_y_mm = 0.0;
  p.ref_x_mm = p.ref_y_mm = 90.0;
  p.ref_z_mm = 15.0;
  p.ref_repeat_um = 0.5;
  p.encoder_offset_x_mm = p.encoder_offset_y_mm = p.encoder_offset_z_mm = 0.0;
  p.touch_gap_um = 1.0;
  p.touch_noise_um = 0.3;
  p.hole_depth_mm = p.hole_x_mm = p.hole_y_mm = 0.0;
  const DrillFigures same = drill(p);
  EXPECT_GT(before.depth_mm, 0.3);
  EXPECT_EQ(same.depth_mm, before.depth_mm);
  EXPECT_EQ(same.removed_mm3, before.removed_mm3);
  EXPECT_EQ(same.wear_mm3, before.wear_mm3);
  EXPECT_EQ(same.z_mm, before.z_mm);
  EXPECT_EQ(same.pulses, before.pulses);
  // With the defaults the encoder reads machine coordinates, and the surface is at Z 0.
  EXPECT_NEAR(before.z_mm, before.machine_z_mm, 0.5e-4);
}

// Moving the work, the electrode's start and the encoders' zero changes where things are, not
// what the gap does: the same pulses, the same hole; only the readings move.
TEST(SimWork, a_work_placed_elsewhere_drills_the_same_and_reads_shifted) {
  const DrillFigures here = drill(SimParams{});
  SimParams p;
  p.work_surface_z_mm = -123.4;
  p.work_origin_x_mm = 40.0;
  p.work_origin_y_mm = -30.0;
  p.start_x_mm = 52.5;
  p.start_y_mm = -27.5;
  p.encoder_offset_z_mm = 7.7;
  p.ref_z_mm = -100.0;  // above the work: the switch plays no part in drilling
  const DrillFigures there = drill(p);
  EXPECT_EQ(there.depth_mm, here.depth_mm);
  EXPECT_EQ(there.removed_mm3, here.removed_mm3);
  EXPECT_EQ(there.pulses, here.pulses);
  EXPECT_NEAR(there.machine_z_mm, here.machine_z_mm - 123.4, 1e-9);
  EXPECT_NEAR(there.z_mm, here.z_mm - 123.4 - 7.7, 1e-4);  // one encoder quantum
}

TEST(SimWork, the_axes_start_at_the_start_position_above_the_moved_surface) {
  SimParams p;
  p.work_surface_z_mm = -80.0;
  p.start_x_mm = 12.0;
  p.start_y_mm = -4.0;
  p.encoder_offset_x_mm = 2.0;
  p.encoder_offset_z_mm = -30.0;
  const Plant plant(p, 1);
  const PlantState& s = plant.state();
  EXPECT_DOUBLE_EQ(s.machine_x_mm, 12.0);
  EXPECT_DOUBLE_EQ(s.machine_y_mm, -4.0);
  EXPECT_NEAR(s.machine_z_mm, -80.0 + p.start_gap_um * 1e-3, 1e-12);
  EXPECT_NEAR(s.x_mm, 10.0, 1e-9);
  EXPECT_NEAR(s.y_mm, -4.0, 1e-9);
  EXPECT_NEAR(s.z_mm, -80.0 + 0.1 + 30.0, 1e-9);
  EXPECT_NEAR(s.gap_um, p.start_gap_um, 1e-9);
}

// --- Encoders ----------------------------------------------------------------------------------

TEST(SimWork, an_encoder_offset_shifts_the_readings_by_exactly_the_offset) {
  SimParams shifted;
  shifted.encoder_offset_x_mm = 12.3456;
  shifted.encoder_offset_y_mm = -0.5;
  shifted.encoder_offset_z_mm = 250.0;
  Plant a(SimParams{}, 3), b(shifted, 3);
  for (const PlantCommands& c : {velocity(5.0, -3.0, 2.0), velocity(-1.0, 0.7, -0.3)}) {
    run_ms(a, c, 137);
    run_ms(b, c, 137);
    EXPECT_EQ(b.state().machine_x_mm, a.state().machine_x_mm);  // the axes move the same
    EXPECT_NEAR(a.state().x_mm - b.state().x_mm, 12.3456, 1e-9);
    EXPECT_NEAR(a.state().y_mm - b.state().y_mm, -0.5, 1e-9);
    EXPECT_NEAR(a.state().z_mm - b.state().z_mm, 250.0, 1e-9);
  }
}

TEST(SimWork, setting_the_actual_position_changes_the_reading_and_not_the_motion) {
  SimParams p;
  p.encoder_offset_x_mm = 3.21;
  Plant plant(p, 5), twin(p, 5);
  run_ms(plant, velocity(2.0, 0.0, 0.0), 100);
  run_ms(twin, velocity(2.0, 0.0, 0.0), 100);
  plant.set_encoder_mm(0, 90.0);
  plant.set_encoder_mm(2, -1.5);
  EXPECT_NEAR(plant.state().x_mm, 90.0, 1e-9);
  EXPECT_NEAR(plant.state().z_mm, -1.5, 1e-9);
  EXPECT_EQ(plant.state().machine_x_mm, twin.state().machine_x_mm);
  // From now on it reads the value plus the true motion since the set.
  const double x0 = plant.state().machine_x_mm, z0 = plant.state().machine_z_mm;
  run_ms(plant, velocity(-4.0, 0.0, 1.0), 250);
  run_ms(twin, velocity(-4.0, 0.0, 1.0), 250);
  EXPECT_EQ(plant.state().machine_x_mm, twin.state().machine_x_mm);
  EXPECT_NEAR(plant.state().x_mm, 90.0 + (plant.state().machine_x_mm - x0), 1e-4);
  EXPECT_NEAR(plant.state().z_mm, -1.5 + (plant.state().machine_z_mm - z0), 1e-4);
  EXPECT_LT(plant.state().machine_x_mm, x0 - 0.5);  // it did move
}

// --- Reference switches ------------------------------------------------------------------------

/// Approaches the X switch slowly from 30 µm below `ref` `n` times, backing off 60 µm in
/// between; returns the machine X of each trip.
std::vector<double> x_trips(const SimParams& p, std::uint64_t seed, int n) {
  Plant plant(p, seed);
  std::vector<double> trips;
  EXPECT_FALSE(plant.state().ref_x);
  for (int k = 0; k < n; ++k) {
    const bool tripped = run_until(
        plant, velocity(0.2, 0.0, 0.0), 2000, [](const PlantState& s) { return s.ref_x; }, 25);
    EXPECT_TRUE(tripped);
    trips.push_back(plant.state().machine_x_mm);
    const double back_to = plant.state().machine_x_mm - 0.06;
    EXPECT_TRUE(run_until(plant, velocity(-2.0, 0.0, 0.0), 2000,
                          [&](const PlantState& s) { return s.machine_x_mm < back_to; }));
    EXPECT_FALSE(plant.state().ref_x);
  }
  return trips;
}

TEST(SimWork, the_reference_switch_trips_at_its_position_with_its_repeatability) {
  SimParams p;
  p.start_x_mm = 89.97;
  const std::vector<double> trips = x_trips(p, 11, 50);
  for (double x : trips) EXPECT_NEAR(x, 90.0, 5 * 0.5e-3);  // five repeat SDs
  // 50 trips: the SD estimate is good to ±10 % (1σ); the step resolution is 5 nm.
  EXPECT_NEAR(sd(trips), 0.5e-3, 0.15e-3) << "SD " << sd(trips) * 1e3 << " um";
  EXPECT_NEAR(mean(trips), 90.0, 3 * 0.5e-3 / std::sqrt(50.0) + 10e-6);
  RecordProperty("ref_switch_sd_um", std::to_string(sd(trips) * 1e3));
  std::printf("reference switch: mean %.5f mm, SD %.3f um over 50 trips\n", mean(trips),
              sd(trips) * 1e3);
}

TEST(SimWork, a_repeatable_switch_with_no_scatter_trips_exactly_at_its_position) {
  SimParams p;
  p.start_x_mm = 89.97;
  p.ref_repeat_um = 0.0;
  for (double x : x_trips(p, 11, 5)) EXPECT_NEAR(x, 90.0, 10e-6);  // within two axis steps
}

TEST(SimWork, the_z_switch_is_in_machine_coordinates_whatever_the_work_and_encoder) {
  SimParams p;
  p.work_surface_z_mm = -200.0;
  p.encoder_offset_z_mm = 1234.0;
  p.ref_z_mm = -199.0;
  Plant plant(p, 2);
  EXPECT_FALSE(plant.state().ref_z);
  ASSERT_TRUE(run_until(
      plant, velocity(0.0, 0.0, 0.5), 5000, [](const PlantState& s) { return s.ref_z; }, 25));
  EXPECT_NEAR(plant.state().machine_z_mm, -199.0, 3e-3);
  EXPECT_NEAR(plant.state().z_mm, -199.0 - 1234.0, 3e-3);
}

// --- Touch sensing ------------------------------------------------------------------------------

TEST(SimWork, touch_mode_never_discharges_even_with_the_generator_on) {
  Plant plant(SimParams{}, 7);
  PlantCommands c = touching(0.0, 0.0, -1.0);  // down through the surface, no stop
  c.generator_armed = c.generator_on = true;
  run_ms(plant, c, 300);
  const PlantState& s = plant.state();
  EXPECT_EQ(s.pulses, 0U);
  EXPECT_EQ(s.removed_mm3, 0.0);
  EXPECT_EQ(s.wear_mm3, 0.0);
  EXPECT_EQ(s.depth_mm, 0.0);
  EXPECT_TRUE(s.touch_contact);  // collisions are not modelled: it stays in contact
  // Switched out of touch mode, the same commands drill.
  c.touch_mode = false;
  c.vz_mm_s = 0.0;
  run_ms(plant, c, 20);
  EXPECT_GT(plant.state().pulses, 0U);
  EXPECT_FALSE(plant.state().touch_contact);
}

TEST(SimWork, the_gap_reads_the_sensing_voltage_until_contact) {
  Plant plant(SimParams{}, 7);
  run_ms(plant, touching(0.0, 0.0, 0.0), 20);
  EXPECT_NEAR(plant.take_sensors().mean_gap_voltage_v, 10.0, 1e-9);
  EXPECT_NEAR(plant.state().gap_voltage_filtered_v, 10.0, 1e-3);
  ASSERT_TRUE(run_until(plant, touching(0.0, 0.0, -0.5), 1000,
                        [](const PlantState& s) { return s.touch_contact; }));
  (void)plant.take_sensors();
  run_ms(plant, touching(0.0, 0.0, 0.0), 5);
  EXPECT_EQ(plant.take_sensors().mean_gap_voltage_v, 0.0);
}

/// Touches the surface `n` times from 8 µm above at 20 µm/s; the tip's height at each contact.
std::vector<double> z_touches(const SimParams& p, std::uint64_t seed, int n) {
  Plant plant(p, seed);
  std::vector<double> heights;
  // Slowly enough that the axis settles (a speed change of Δv overshoots by ≈ Δv/ω_n).
  run_until(
      plant, touching(0.0, 0.0, -0.2), 1000, [](const PlantState& s) { return s.gap_um < 10.0; },
      25);
  for (int k = 0; k < n; ++k) {
    EXPECT_TRUE(run_until(
        plant, touching(0.0, 0.0, -0.02), 2000, [](const PlantState& s) { return s.touch_contact; },
        25));
    heights.push_back(plant.state().gap_um);  // the tip above the surface (no wear)
    EXPECT_TRUE(run_until(
        plant, touching(0.0, 0.0, 0.2), 2000, [](const PlantState& s) { return s.gap_um > 8.0; },
        25));
    EXPECT_FALSE(plant.state().touch_contact);
  }
  return heights;
}

TEST(SimWork, a_z_touch_over_material_senses_the_surface_within_the_touch_gap) {
  SimParams p;
  p.work_surface_z_mm = -42.0;  // where it is does not matter
  const std::vector<double> h = z_touches(p, 21, 30);
  for (double x : h) {
    EXPECT_GT(x, 1.0 - 4 * 0.3 - 0.01);
    EXPECT_LT(x, 1.0 + 4 * 0.3 + 0.01);
  }
  EXPECT_NEAR(mean(h), 1.0, 3 * 0.3 / std::sqrt(30.0) + 0.01);
  EXPECT_NEAR(sd(h), 0.3, 0.12);
  std::printf("Z touch: tip %.3f um above the surface, SD %.3f um over 30 touches\n", mean(h),
              sd(h));
}

TEST(SimWork, a_z_touch_over_the_bore_finds_nothing) {
  SimParams p;
  p.work_origin_x_mm = 10.0;
  p.work_bore_x_mm = 5.0;  // the bore's centre at machine X 15
  p.work_bore_d_mm = 4.0;
  p.start_x_mm = 15.5;  // the Ø1 tube is inside the Ø4 bore
  Plant plant(p, 4);
  run_until(plant, touching(0.0, 0.0, -2.0), 1000,
            [](const PlantState& s) { return s.touch_contact; });
  EXPECT_FALSE(plant.state().touch_contact);
  EXPECT_LT(plant.state().machine_z_mm, -1.5);  // well below the surface, inside the bore
}

TEST(SimWork, an_x_edge_touch_below_the_surface_senses_the_face) {
  SimParams p;
  p.work_origin_x_mm = 7.0;  // the +X face at machine X 57
  p.start_x_mm = 60.0;
  Plant plant(p, 9);
  run_ms(plant, velocity(0.0, 0.0, -10.0), 200);  // beside the work, 2 mm down
  ASSERT_LT(plant.state().machine_z_mm, -1.0);
  EXPECT_FALSE(plant.state().touch_contact);
  // Fast to 0.1 mm from the face (a stop from 5 mm/s overshoots by tens of µm), then slowly.
  ASSERT_TRUE(run_until(
      plant, touching(-5.0, 0.0, 0.0), 1000,
      [](const PlantState& s) { return s.machine_x_mm < 57.6; }, 25));
  EXPECT_FALSE(plant.state().touch_contact);
  ASSERT_TRUE(run_until(
      plant, touching(-0.02, 0.0, 0.0), 8000, [](const PlantState& s) { return s.touch_contact; },
      25));
  const double side_gap_um = (plant.state().machine_x_mm - 0.5 - 57.0) * 1e3;
  EXPECT_GT(side_gap_um, 1.0 - 4 * 0.3);
  EXPECT_LT(side_gap_um, 1.0 + 4 * 0.3 + 0.01);
}

TEST(SimWork, a_sinking_electrode_touches_an_edge_with_its_side) {
  SimParams p = *SimParams::preset("sink");  // a 10 × 10 mm block electrode
  p.start_y_mm = -70.0;                      // the −Y face at −50
  Plant plant(p, 9);
  run_ms(plant, velocity(0.0, 0.0, -10.0), 100);
  ASSERT_TRUE(run_until(
      plant, touching(0.0, 5.0, 0.0), 5000,
      [](const PlantState& s) { return s.machine_y_mm > -55.1; }, 25));
  ASSERT_TRUE(run_until(
      plant, touching(0.0, 0.02, 0.0), 8000, [](const PlantState& s) { return s.touch_contact; },
      25));
  EXPECT_NEAR((-50.0 - (plant.state().machine_y_mm + 5.0)) * 1e3, 1.0, 4 * 0.3 + 0.01);
}

/// From the bore's centre region, touches the wall in +x, −x, +y, −y; the machine XY at each.
std::vector<double> bore_touches(Plant& plant) {
  std::vector<double> at;
  const double dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (const auto& d : dirs) {
    const double x0 = plant.state().machine_x_mm, y0 = plant.state().machine_y_mm;
    // Fast to within 0.1 mm of the wall would need to know it: approach at 0.5 mm/s instead.
    EXPECT_TRUE(run_until(
        plant, touching(0.5 * d[0], 0.5 * d[1], 0.0), 20000,
        [](const PlantState& s) { return s.touch_contact; }, 25));
    at.push_back(d[0] != 0 ? plant.state().machine_x_mm : plant.state().machine_y_mm);
    EXPECT_TRUE(run_until(
        plant, touching(-2.0 * d[0], -2.0 * d[1], 0.0), 5000,
        [&](const PlantState& s) {
          return std::hypot(s.machine_x_mm - x0, s.machine_y_mm - y0) < 0.01;
        },
        25));
    EXPECT_FALSE(plant.state().touch_contact);
  }
  return at;
}

TEST(SimWork, inside_the_bore_each_wall_is_touched_and_the_centre_found) {
  SimParams p;
  p.work_origin_x_mm = 3.0;
  p.work_origin_y_mm = -2.0;
  p.work_bore_x_mm = 10.0;
  p.work_bore_y_mm = 5.0;  // centre at machine (13, 3)
  p.work_bore_d_mm = 3.0;
  p.start_x_mm = 13.2;  // off centre
  p.start_y_mm = 2.9;
  Plant plant(p, 17);
  run_ms(plant, velocity(0.0, 0.0, -10.0), 200);  // 2 mm into the bore
  EXPECT_FALSE(plant.state().touch_contact);
  const std::vector<double> w = bore_touches(plant);
  ASSERT_EQ(w.size(), 4U);
  // The tube (r 0.5) meets the wall (R 1.5) where its centre is 1 mm less the touch gap from the
  // bore's centre: along the chords through the start (0.1 mm off in Y, 0.2 mm off in X).
  const double reach = 1.0 - 1e-3;
  const double tol = 4 * 0.3e-3 + 0.05e-3;  // the gap's noise, the 12.5 nm steps
  EXPECT_NEAR(w[0], 13.0 + std::sqrt(reach * reach - 0.01), tol);
  EXPECT_NEAR(w[1], 13.0 - std::sqrt(reach * reach - 0.01), tol);
  EXPECT_NEAR(w[2], 3.0 + std::sqrt(reach * reach - 0.04), tol);
  EXPECT_NEAR(w[3], 3.0 - std::sqrt(reach * reach - 0.04), tol);
  // The midpoints are the centre whatever the start (two noisy gaps: within about 1 µm).
  EXPECT_NEAR((w[0] + w[1]) / 2.0, 13.0, 1e-3);
  EXPECT_NEAR((w[2] + w[3]) / 2.0, 3.0, 1e-3);
}

// --- The hole -----------------------------------------------------------------------------------

TEST(SimWork, the_hole_is_reported_in_work_coordinates_with_the_datum_moved) {
  SimParams p;
  p.servo_gain_mm_s_per_v = 0.05;
  p.work_origin_x_mm = 2.0;
  p.work_origin_y_mm = 1.0;
  p.start_x_mm = 12.0;
  p.start_y_mm = -3.0;
  Plant plant(p, 5);
  PlantCommands c;
  c.generator_armed = c.generator_on = true;
  c.servo_ref_v = 40.0;
  run_ms(plant, c, 500);
  const PlantState& s = plant.state();
  EXPECT_GT(s.hole_depth_mm, 0.05);
  EXPECT_DOUBLE_EQ(s.hole_depth_mm, s.depth_mm);
  EXPECT_DOUBLE_EQ(s.hole_x_mm, 12.0);
  EXPECT_DOUBLE_EQ(s.hole_y_mm, -3.0);
  EXPECT_DOUBLE_EQ(s.hole_work_x_mm, 10.0);
  EXPECT_DOUBLE_EQ(s.hole_work_y_mm, -4.0);
  // Up and 5 mm sideways: the electrode is over fresh work, the hole is kept where it is.
  run_ms(plant, velocity(0.0, 0.0, 20.0), 100);
  run_ms(plant, velocity(10.0, 0.0, 0.0), 500);
  EXPECT_EQ(plant.state().depth_mm, 0.0);
  EXPECT_DOUBLE_EQ(plant.state().hole_work_x_mm, 10.0);
  EXPECT_GT(plant.state().hole_depth_mm, 0.05);
}

TEST(SimWork, a_hole_set_in_the_work_is_continued_where_it_is_and_only_there) {
  SimParams p;
  p.servo_gain_mm_s_per_v = 0.05;
  p.start_x_mm = -20.0;
  p.start_y_mm = 10.0;
  PlantCommands c;
  c.generator_armed = c.generator_on = true;
  c.servo_ref_v = 40.0;
  const double area = std::acos(-1.0) / 4.0 * p.hole_d_mm * p.hole_d_mm;

  Plant over(p, 5);  // the electrode is over the hole: the servo finds its bottom and goes on
  over.set_hole_mm(-20.0, 10.0, 2.0);
  EXPECT_EQ(over.state().depth_mm, 2.0);
  run_ms(over, c, 1500);
  EXPECT_GT(over.state().depth_mm, 2.2);
  EXPECT_NEAR(over.state().removed_mm3, (over.state().depth_mm - 2.0) * area, 1e-9);

  Plant beside(p, 5);  // the same hole 3 mm away: the electrode drills a new one from the top
  beside.set_hole_mm(-17.0, 10.0, 2.0);
  EXPECT_EQ(beside.state().depth_mm, 0.0);
  EXPECT_EQ(beside.state().hole_depth_mm, 2.0);
  run_ms(beside, c, 1500);
  EXPECT_GT(beside.state().depth_mm, 0.2);
  EXPECT_LT(beside.state().depth_mm, 2.0);
  EXPECT_DOUBLE_EQ(beside.state().hole_x_mm, -20.0);  // the new hole; the other is forgotten
  EXPECT_NEAR(beside.state().removed_mm3, beside.state().depth_mm * area, 1e-9);
}

TEST(SimWork, a_z_touch_over_a_drilled_hole_finds_its_bottom) {
  SimParams p;
  p.hole_depth_mm = 3.0;  // set at load: the hole is there from power-on
  p.hole_x_mm = 0.0;
  p.hole_y_mm = 0.0;
  Plant plant(p, 4);
  run_until(plant, touching(0.0, 0.0, -2.0), 3000,
            [](const PlantState& s) { return s.machine_z_mm < -2.9; });
  ASSERT_TRUE(run_until(
      plant, touching(0.0, 0.0, -0.02), 6000, [](const PlantState& s) { return s.touch_contact; },
      25));
  EXPECT_NEAR(plant.state().machine_z_mm, -3.0 + 1e-3, 4 * 0.3e-3 + 1e-5);
}

// --- The driver's pins and the retained hole ----------------------------------------------------

void run_cycles(rt::Runtime& r, int from, int cycles) {
  rt::VirtualClock clock;
  auto& task = *r.tasks()[0];
  for (int k = from; k < from + cycles; ++k) {
    const rt::TimePoint release{1ms * k};
    clock.advance_to(release);
    task.run_cycle(release, clock);
  }
}

Plant& plant_of(rt::Runtime& r) { return dynamic_cast<SimDriver&>(r.driver()).plant(); }

TEST(SimWork, the_driver_pins_touch_set_positions_and_report_switches_and_the_hole) {
  const auto& regs = test::sim_registries();
  const std::string yaml = R"(version: 1
machine:
  name: touch
  io:
    driver: sim
    params: {preset: drill, seed: 3, work_surface_z_mm: -50, encoder_offset_z_mm: 10,
             start_x_mm: 5, work_origin_x_mm: 2, ref_z_mm: -49.95}
tasks:
  - {name: servo, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: g, type: Gain}
    wires:
      g.in: io.z_mm
      io.touch_mode: true
      io.gen_arm: true
      io.gen_on: true
      io.vz_cmd: -0.2
      io.pos_set_x: true
      io.pos_value_x_mm: 123.5
)";
  auto r = rt::Runtime::build(rt::parse_config_text(yaml, "m.yaml"), regs.first, regs.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  auto read = [&](const char* name) { return r->variables().read(name).value(); };
  run_cycles(*r, 0, 2);
  EXPECT_NEAR(read("io.x_mm"), 123.5, 1e-9);  // set on the first write, the axis never moved
  EXPECT_NEAR(plant_of(*r).state().machine_x_mm, 5.0, 1e-12);
  EXPECT_EQ(read("io.ref_z"), 1.0);  // 0.1 mm above the surface is above −49.95
  EXPECT_EQ(read("io.contact"), 0.0);
  EXPECT_NEAR(read("io.z_mm"), -49.9 - 10.0, 1e-3);
  EXPECT_NEAR(read("io.hole_work_x_mm"), 3.0, 1e-12);  // no hole yet: under the electrode
  int k = 2;
  for (; k < 1000 && read("io.contact") == 0.0; ++k) run_cycles(*r, k, 1);
  EXPECT_EQ(read("io.contact"), 1.0);
  // The surface reads −50 − 10; contact 1 µm above it (± its noise and one cycle at 0.2 mm/s).
  EXPECT_NEAR(read("io.z_mm"), -60.0 + 1e-3, 4 * 0.3e-3 + 0.2e-3 + 0.1e-3);
  EXPECT_EQ(read("io.ref_z"), 0.0);
  run_cycles(*r, k, 50);  // on down: collisions are not modelled, it stays in contact
  EXPECT_EQ(read("io.contact"), 1.0);
  EXPECT_EQ(plant_of(*r).state().pulses, 0U);
  EXPECT_EQ(read("io.gap_voltage_v"), 0.0);
}

std::unique_ptr<rt::Runtime> build_retained(const std::string& retain_file) {
  const auto& regs = test::sim_registries();
  const std::string yaml = R"(version: 1
machine:
  name: retained-hole
  io:
    driver: sim
    params: {preset: drill, seed: 1000, servo_gain_mm_s_per_v: 0.05, start_x_mm: -20,
             start_y_mm: 10, work_origin_x_mm: -30}
tasks:
  - {name: servo, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: g, type: Gain}
    wires:
      g.in: io.depth_mm
      io.servo_ref_v: 40
      io.gen_arm: true
      io.gen_on: true
retain:
  file: )" + retain_file + R"(
  variables: [io.electrode_length_mm, io.hole_depth_mm, io.hole_x_mm, io.hole_y_mm]
)";
  auto r = rt::Runtime::build(rt::parse_config_text(yaml, "m.yaml"), regs.first, regs.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  return r;
}

TEST(SimWork, a_retained_hole_is_still_there_after_a_restart_and_drilling_continues_it) {
  edm::test::TempDir dir("edm-sim-hole");
  double depth = 0.0;
  {
    auto r = build_retained(dir.file("retain.dat"));
    EXPECT_EQ(r->variables().read("io.hole_depth_mm").value(), 0.0);
    run_cycles(*r, 0, 2000);
    depth = plant_of(*r).state().depth_mm;
    EXPECT_GT(depth, 0.4);
    EXPECT_DOUBLE_EQ(r->variables().read("io.hole_depth_mm").value(), depth);
    EXPECT_DOUBLE_EQ(r->variables().read("io.hole_x_mm").value(), -20.0);
    EXPECT_DOUBLE_EQ(r->variables().read("io.hole_y_mm").value(), 10.0);
    EXPECT_DOUBLE_EQ(r->variables().read("io.hole_work_x_mm").value(), 10.0);
    ASSERT_NE(r->retain(), nullptr);
    EXPECT_TRUE(r->retain()->flush());
  }  // kill -9: nothing else survives
  auto r = build_retained(dir.file("retain.dat"));
  const PlantState& st = plant_of(*r).state();
  EXPECT_DOUBLE_EQ(st.hole_depth_mm, depth);
  EXPECT_DOUBLE_EQ(st.depth_mm, depth);  // the electrode powers on over it
  EXPECT_DOUBLE_EQ(st.hole_x_mm, -20.0);
  EXPECT_DOUBLE_EQ(st.removed_mm3, 0.0);
  run_cycles(*r, 0, 2000);  // down through the hole to its bottom, then on
  EXPECT_GT(st.depth_mm, depth + 0.2);
  const double area = std::acos(-1.0) / 4.0 * 1.1 * 1.1;
  EXPECT_NEAR(st.removed_mm3, (st.depth_mm - depth) * area, 1e-9);
}

TEST(SimWork, the_hole_figures_are_writable_at_run_time_one_at_a_time) {
  edm::test::TempDir dir("edm-sim-hole");
  auto r = build_retained(dir.file("retain.dat"));
  auto& vars = r->variables();
  EXPECT_TRUE(vars.write("io.hole_depth_mm", 4.0, /*apply_now=*/true));
  EXPECT_TRUE(vars.write("io.hole_x_mm", -21.0, true));  // depth and y stay
  EXPECT_DOUBLE_EQ(plant_of(*r).state().hole_depth_mm, 4.0);
  EXPECT_DOUBLE_EQ(plant_of(*r).state().hole_x_mm, -21.0);
  EXPECT_DOUBLE_EQ(plant_of(*r).state().hole_y_mm, 10.0);
  EXPECT_DOUBLE_EQ(vars.read("io.hole_x_mm").value(), -21.0);
  EXPECT_FALSE(vars.write("io.hole_depth_mm", -1.0, true));
  const rt::VarStatus refused = vars.write("io.work_surface_z_mm", 10.0, true);
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.message.find("load time only"), std::string::npos) << refused.message;
}

// --- Validation ---------------------------------------------------------------------------------

TEST(SimWork, a_work_block_must_have_extent_and_a_bore_must_lie_inside_it) {
  SimParams p;
  p.work_x_min_mm = 10.0;
  p.work_x_max_mm = 10.0;
  EXPECT_TRUE(has_error(p.validate(), "work_x_max_mm"));
  p = SimParams{};
  p.work_y_min_mm = 5.0;
  p.work_y_max_mm = -5.0;
  EXPECT_TRUE(has_error(p.validate(), "work_y_max_mm"));
  p = SimParams{};
  p.work_bore_d_mm = -1.0;
  EXPECT_TRUE(has_error(p.validate(), "work_bore_d_mm"));
  p = SimParams{};
  p.work_bore_d_mm = 10.0;
  p.work_bore_x_mm = 46.0;  // reaches X 51, past the block's +X face at 50
  EXPECT_TRUE(has_error(p.validate(), "work_bore_d_mm"));
  p.work_bore_x_mm = 44.0;
  EXPECT_TRUE(p.validate().empty());
  p.work_bore_y_mm = -46.0;
  EXPECT_TRUE(has_error(p.validate(), "work_bore_d_mm"));
  p = SimParams{};
  for (double SimParams::*f : {&SimParams::ref_repeat_um, &SimParams::touch_gap_um,
                               &SimParams::touch_noise_um, &SimParams::hole_depth_mm}) {
    SimParams q;
    q.*f = -0.1;
    EXPECT_FALSE(q.validate().empty());
  }
  p.work_surface_z_mm = std::nan("");
  EXPECT_TRUE(has_error(p.validate(), "work_surface_z_mm"));
}

}  // namespace
}  // namespace edm::sim
