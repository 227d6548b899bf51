#pragma once
// Off-line electrode-wear pre-compensation of seed 004, eq. (9)-(11), used by the HMI's
// interpreter on drilling blocks (and by anything else that plans a drilling depth).
//
//   (9)  Tw = lz / (MRRw / A)       machining time of a Z block of length lz
//   (10) δ  = Vd·Tw = MRRe·lz/MRRw  electrode length worn meanwhile (Vd = MRRe/A, eq. 8)
//   (11) lz' = lz + δ               the Z travel actually commanded
// With the condition's volumetric wear ratio θ = MRRe/MRRw this is δ = θ·lz: the electrode and the
// hole are taken to have the same cross-section A, as in the paper (for a tube electrode whose
// hole is wider than its section the RT compensator's area ratio refines this; docs/blocks.md).

namespace edm::machining {

struct WearPrecomp {
  double delta_mm{0.0};   // δ, eq. (10)
  double travel_mm{0.0};  // lz' = lz + δ, eq. (11)
};

/// lz ≥ 0 the nominal Z block length (mm), wear_ratio ≥ 0 the condition's θ = MRRe/MRRw.
/// Negative or non-finite inputs give {0, lz} unchanged (the caller validates its inputs).
WearPrecomp wear_precompensate(double lz_mm, double wear_ratio) noexcept;

/// Eq. (9): machining time of lz at the workpiece removal rate mrr_w (mm³/s) through area A
/// (mm²); 0 when mrr_w ≤ 0.
double machining_time_s(double lz_mm, double mrr_w_mm3_s, double area_mm2) noexcept;

}  // namespace edm::machining
