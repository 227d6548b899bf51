#pragma once
// Off-line electrode-wear pre-compensation of seed 004, eq. (9)-(11), used by the HMI's
// interpreter on drilling blocks (and by anything else that plans a drilling depth).
//
//   (9)  Tw = lz / (MRRw / A)       machining time of a Z block of length lz
//   (10) δ  = Vd·Tw = MRRe·lz/MRRw  electrode length worn meanwhile (Vd = MRRe/A, eq. 8)
//   (11) lz' = lz + δ               the Z travel actually commanded
// The paper writes one A for both; a tube electrode's section A_e is smaller than the hole's
// A_hole, and eq. (8) (Vd = MRRe/A_e) and eq. (9) (the hole bottom advances at MRRw/A_hole) then
// give
//   (10) δ = (MRRe/A_e)·(lz·A_hole/MRRw) = θ·(A_hole/A_e)·lz,   θ = MRRe/MRRw,
// the same area ratio the real-time compensator (WearCompensator, eq. 8) uses, so the planned
// travel lz' and the travel eq. (8) produces agree. lz is the depth actually eroded: the part of
// the block below the work surface (Z0 of the program), no wear is planned for the air above it.

#include <cstdint>
#include <span>
#include <vector>

#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::machining {

struct WearPrecomp {
  double delta_mm{0.0};   // δ, eq. (10)
  double travel_mm{0.0};  // lz' = lz + δ, eq. (11)
};

/// lz ≥ 0 the depth eroded by the block (mm), wear_ratio ≥ 0 the condition's θ = MRRe/MRRw,
/// area_ratio > 0 its A_hole/A_e. Negative or non-finite inputs give {0, lz} unchanged (the caller
/// validates its inputs).
WearPrecomp wear_precompensate(double lz_mm, double wear_ratio, double area_ratio = 1.0) noexcept;

/// Eq. (9): machining time of lz at the workpiece removal rate mrr_w (mm³/s) through area A
/// (mm²); 0 when mrr_w ≤ 0.
double machining_time_s(double lz_mm, double mrr_w_mm3_s, double area_mm2) noexcept;

/// One drilling block of a program and the electrode wear planned through it.
struct HoleWear {
  std::size_t block{0};     // index in the program
  std::int32_t line{0};     // its G-code line
  double cumulative_mm{0};  // Σ δ (eq. 10) of the program's drilling blocks up to this one
};
/// The wear a program is planned with, hole by hole: δ of each drilling block's depth still to
/// erode (depth_mm − depth_done_mm; a machine-coordinate program's −target.z) at its
/// condition's θ and A_hole/A_e, as the interpreter plans it. A block of an unknown condition plans
/// no wear (check_program refuses it).
std::vector<HoleWear> planned_wear(std::span<const MotionBlock> program,
                                   const MachineTables& tables);

}  // namespace edm::machining
