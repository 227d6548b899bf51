#include "params_visit.hpp"

// The machine's part of SimParams::visit (params_visit.hpp): the electrode, the work on the
// machine with its reference switches, encoders and touch mode, the axes.

namespace edm::sim {

namespace rt = edm::rt;

void visit_electrode(SimParams& p, rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("tool_kind", p.tool_kind, {.unit = "", .description = "tube | block | wire"});
  v.param("tool_od_mm", p.tool_od_mm, {.unit = "mm", .description = "tube outer diameter"});
  v.param("tool_id_mm", p.tool_id_mm, {.unit = "mm", .description = "tube inner diameter"});
  v.param("hole_d_mm", p.hole_d_mm, {.unit = "mm", .description = "tube: initial hole diameter"});
  v.param("side_gap_mm", p.side_gap_mm, {.unit = "mm", .description = "block: side gap per side"});
  v.param("tool_width_mm", p.tool_width_mm, {.unit = "mm", .description = "block width"});
  v.param("tool_length_mm", p.tool_length_mm, {.unit = "mm", .description = "block length"});
  v.param("wire_d_mm", p.wire_d_mm, {.unit = "mm", .description = "wire diameter D"});
  // Through `writable`, runtime-writable: the retained electrode length is restored through this
  // (§5a). Its range: 100 km, the wire on a spool (20 kg of Ø0.25 mm brass is ~48 km; the wire
  // preset has 1 km); the hole's below: 5 m, beyond any EDM machine's travel.
  writable.param("electrode_length_mm", p.electrode_length_mm,
                 {.unit = "mm",
                  .description = "electrode length; reads the length left, a runtime write sets it",
                  .range = rt::closed(0.0, 1.0e8)});
  v.param(
      "work_thickness_mm", p.work_thickness_mm,
      {.unit = "mm", .description = "through at this depth (0: blind)", .range = rt::kNonNegative});
  v.param("start_gap_um", p.start_gap_um,
          {.unit = "um",
           .description = "tip above the work surface at start",
           .range = rt::kNonNegative});
  v.param("initial_depth_mm", p.initial_depth_mm,
          {.unit = "mm",
           .description = "tube/block: a hole this deep is already there under the electrode; the "
                          "tip starts start_gap_um above its bottom",
           .range = rt::kNonNegative});
}

void visit_work(SimParams& p, rt::ParamVisitor& v, rt::ParamVisitor& writable) {
  v.param("work_surface_z_mm", p.work_surface_z_mm,
          {.unit = "mm", .description = "machine Z of the work's top surface"});
  v.param("work_origin_x_mm", p.work_origin_x_mm,
          {.unit = "mm", .description = "machine X of the work's datum"});
  v.param("work_origin_y_mm", p.work_origin_y_mm,
          {.unit = "mm", .description = "machine Y of the work's datum"});
  v.param("work_x_min_mm", p.work_x_min_mm,
          {.unit = "mm", .description = "work block: lowest X, relative to the datum"});
  v.param("work_x_max_mm", p.work_x_max_mm,
          {.unit = "mm", .description = "work block: highest X, relative to the datum (> min)"});
  v.param("work_y_min_mm", p.work_y_min_mm,
          {.unit = "mm", .description = "work block: lowest Y, relative to the datum"});
  v.param("work_y_max_mm", p.work_y_max_mm,
          {.unit = "mm", .description = "work block: highest Y, relative to the datum (> min)"});
  v.param("work_bore_x_mm", p.work_bore_x_mm,
          {.unit = "mm", .description = "through bore: centre X relative to the datum"});
  v.param("work_bore_y_mm", p.work_bore_y_mm,
          {.unit = "mm", .description = "through bore: centre Y relative to the datum"});
  v.param("work_bore_d_mm", p.work_bore_d_mm,
          {.unit = "mm",
           .description = "through bore diameter, inside the block (0: none)",
           .range = rt::kNonNegative});
  v.param("start_x_mm", p.start_x_mm,
          {.unit = "mm", .description = "machine X of the electrode at power-on"});
  v.param("start_y_mm", p.start_y_mm,
          {.unit = "mm", .description = "machine Y of the electrode at power-on"});
  v.param("ref_x_mm", p.ref_x_mm,
          {.unit = "mm", .description = "X reference switch: on at or beyond this machine X"});
  v.param("ref_y_mm", p.ref_y_mm,
          {.unit = "mm", .description = "Y reference switch: on at or beyond this machine Y"});
  v.param("ref_z_mm", p.ref_z_mm,
          {.unit = "mm", .description = "Z reference switch: on at or beyond this machine Z"});
  v.param("ref_repeat_um", p.ref_repeat_um,
          {.unit = "um",
           .description = "reference switches: SD of the trip point, drawn anew per trip",
           .range = rt::kNonNegative});
  v.param("ref_hysteresis_um", p.ref_hysteresis_um,
          {.unit = "um",
           .description = "reference switches: release this far below the trip point",
           .range = rt::kNonNegative});
  v.param("encoder_offset_x_mm", p.encoder_offset_x_mm,
          {.unit = "mm", .description = "X encoder reads machine X - this at power-on"});
  v.param("encoder_offset_y_mm", p.encoder_offset_y_mm,
          {.unit = "mm", .description = "Y encoder reads machine Y - this at power-on"});
  v.param("encoder_offset_z_mm", p.encoder_offset_z_mm,
          {.unit = "mm", .description = "Z encoder reads machine Z - this at power-on"});
  v.param("touch_gap_um", p.touch_gap_um,
          {.unit = "um",
           .description = "touch mode: contact within this distance of the work's material",
           .range = rt::kNonNegative});
  v.param("touch_noise_um", p.touch_noise_um,
          {.unit = "um",
           .description = "touch mode: SD of that distance, drawn anew per contact",
           .range = rt::kNonNegative});
  v.param("touch_voltage_v", p.touch_voltage_v,
          {.unit = "V",
           .description = "touch mode: gap voltage while open (0 V in contact)",
           .range = rt::kNonNegative});
  // Through `writable`, runtime-writable: a retain store restores the hole through these
  // (docs/simulator.md §5a).
  writable.param("hole_depth_mm", p.hole_depth_mm,
                 {.unit = "mm",
                  .description = "the hole in the work: reads its live depth, a write sets it",
                  .range = rt::closed(0.0, 5000.0)});
  writable.param("hole_x_mm", p.hole_x_mm,
                 {.unit = "mm",
                  .description = "the hole's axis, machine X: reads the live one, a write sets it",
                  .range = rt::closed(-5000.0, 5000.0)});
  writable.param("hole_y_mm", p.hole_y_mm,
                 {.unit = "mm",
                  .description = "the hole's axis, machine Y: reads the live one, a write sets it",
                  .range = rt::closed(-5000.0, 5000.0)});
}

void visit_axes(SimParams& p, rt::ParamVisitor& v) {
  v.param(
      "axis_wn_rad_s", p.axis_wn_rad_s,
      {.unit = "rad/s", .description = "position loop natural frequency", .range = rt::kPositive});
  v.param("axis_zeta", p.axis_zeta,
          {.unit = "1", .description = "position loop damping", .range = rt::kPositive});
  v.param("v_max_mm_s", p.v_max_mm_s,
          {.unit = "mm/s",
           .description = "feed speed limit (toward the work, x, y)",
           .range = rt::kPositive});
  v.param("v_jump_mm_s", p.v_jump_mm_s,
          {.unit = "mm/s",
           .description = "retract speed limit (z away from the work)",
           .range = rt::kPositive});
  v.param("a_max_mm_s2", p.a_max_mm_s2,
          {.unit = "mm/s2", .description = "acceleration limit", .range = rt::kPositive});
  v.param("encoder_um", p.encoder_um,
          {.unit = "um",
           .description = "encoder quantum of reported positions",
           .range = rt::kNonNegative});
  v.param(
      "servo_gain_mm_s_per_v", p.servo_gain_mm_s_per_v,
      {.unit = "mm/s/V",
       .description =
           "machine servo gain k: vz += -k (U_av - servo_ref_v) while servo_ref_v > 0 (0: none)",
       .range = rt::kNonNegative});
  v.param(
      "axis_step_us", p.axis_step_us,
      {.unit = "us", .description = "axis integration sub-step", .range = rt::closed(1.0, 50.0)});
}

}  // namespace edm::sim
