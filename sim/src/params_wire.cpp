#include "params_visit.hpp"

// The wire-cutting part of SimParams::visit (params_visit.hpp): the part's profile, wire
// breakage, kerf debris, the nozzle, the internal hole and cavity (§6.4).

namespace edm::sim {

namespace rt = edm::rt;

void visit_wire(SimParams& p, rt::ParamVisitor& v) {
  v.param("wire_thickness_profile", p.wire_thickness_profile,
          {.unit = "mm:mm", .description = "cut length:thickness,..."});
  v.param("wire_hole_from_mm", p.wire_hole_from_mm,
          {.unit = "mm",
           .description = "internal hole starts at this length",
           .range = rt::kNonNegative});
  v.param("wire_hole_to_mm", p.wire_hole_to_mm,
          {.unit = "mm", .description = "internal hole ends at this length"});
  v.param("wire_ibk_ref_a", p.wire_ibk_ref_a,
          {.unit = "A",
           .description = "break current I_BK at H = 10 mm, f = 1",
           .range = rt::kPositive});
  v.param(
      "wire_flush_floor", p.wire_flush_floor,
      {.unit = "1", .description = "f = floor + (1 - floor) F_eff", .range = rt::closed(0.0, 1.0)});
  v.param("wire_break_current_ms", p.wire_break_current_ms,
          {.unit = "ms", .description = "break after mean I > I_BK this", .range = rt::kPositive});
  v.param("wire_break_rab", p.wire_break_rab,
          {.unit = "1",
           .description = "rupture hazard: at this Rab ...",
           .range = rt::closed(0.0, 1.0)});
  v.param(
      "wire_break_rab_ms", p.wire_break_rab_ms,
      {.unit = "ms", .description = "... the mean time to break is this", .range = rt::kPositive});
  v.param("wire_break_rab_width", p.wire_break_rab_width,
          {.unit = "1", .description = "hazard x e per this Rab above", .range = rt::kPositive});
  v.param("wire_break_rab_tau_ms", p.wire_break_rab_tau_ms,
          {.unit = "ms", .description = "hazard acts on Rab lagged by", .range = rt::kPositive});
  v.param("wire_break_rab_shape", p.wire_break_rab_shape,
          {.unit = "1",
           .description = "k: tolerated damage ~ Gamma(k, 1/k), a whole number",
           .range = rt::closed(1.0, static_cast<double>(kMaxWireBreakShape))});
  v.param("wire_kerf_debris_per_mm", p.wire_kerf_debris_per_mm,
          {.unit = "1/mm",
           .description = "kerf debris c_k added per mm of cut (0 = no kerf debris)",
           .range = rt::kNonNegative});
  v.param("wire_kerf_flush_s", p.wire_kerf_flush_s,
          {.unit = "s",
           .description = "tau_k of the kerf debris at H = 10 mm",
           .range = rt::kPositive});
  v.param("wire_kerf_flush_exp", p.wire_kerf_flush_exp,
          {.unit = "1", .description = "tau_k grows as (H/10 mm)^this", .range = rt::kNonNegative});
  v.param("wire_nozzle_radius_mm", p.wire_nozzle_radius_mm,
          {.unit = "mm", .description = "flushing nozzle radius", .range = rt::kNonNegative});
  v.param("wire_hole_flush_factor", p.wire_hole_flush_factor,
          {.unit = "1",
           .description = "F_eff x this while the nozzle overlaps the internal hole",
           .range = rt::closed(0.0, 1.0)});
  v.param("wire_cavity_from_mm", p.wire_cavity_from_mm,
          {.unit = "mm",
           .description = "internal cavity starts at this length",
           .range = rt::kNonNegative});
  v.param("wire_cavity_to_mm", p.wire_cavity_to_mm,
          {.unit = "mm", .description = "internal cavity ends (far wall) here"});
  v.param("wire_cavity_height_mm", p.wire_cavity_height_mm,
          {.unit = "mm",
           .description = "void height of the cavity, centred in H, < H over the cavity",
           .range = rt::kNonNegative});
  v.param("wire_cavity_flush_factor", p.wire_cavity_flush_factor,
          {.unit = "1",
           .description = "flush of the wire's centre part at the cavity's far wall",
           .range = rt::closed(0.0, 1.0)});
  v.param("wire_cavity_flush_mm", p.wire_cavity_flush_mm,
          {.unit = "mm",
           .description = "that flush loss fades e-fold per this much cut past the far wall",
           .range = rt::kPositive});
  v.param("wire_cavity_debris", p.wire_cavity_debris,
          {.unit = "1",
           .description = "debris of the cavity's stagnant dielectric, met at the far wall",
           .range = rt::closed(0.0, 1.0)});
  v.param("mean_current_ema_ms", p.mean_current_ema_ms,
          {.unit = "ms", .description = "time constant of mean current", .range = rt::kPositive});
}

}  // namespace edm::sim
