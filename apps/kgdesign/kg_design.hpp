#pragma once
// Design helper for the P gap controller of SEEDS 004 (eq. 1–3): Vz = Kg·(Tdr − Td), with Kg chosen
// to minimise the integral of the squared error J = ∫₀^∞ e²(t) dt for a step in Tdr, evaluated with
// the closed-form tables of integral-square values (Jury & Dewey 1965) for orders 1…4.
//
// Linearised loop (units: gap µm, Td µs, time s, Vz mm/s, Kg (mm/s)/µs):
//   Td:    ΔTd = kd·Δg,  kd = dτ_med/dg at the working gap [µs/µm], the slope of the
//          simulator's own law (td_law.hpp, td_gap_slope_us_per_um)
//   gap:   Δg' = 1000·vz − erosion  [µm/s]; vz the Z velocity in mm/s, Z positive upward, so a
//          positive vz (back off) opens the gap. The erosion rate is a disturbance, dropped here.
//   axis:  velocity command → velocity, G_axis(0) = 1, either first order 1/(τ_v·s + 1)
//          or second order ω_n²/(s² + 2ζω_n·s + ω_n²)
//   meas.: optional first-order lag on the measured Td, 1/(τ_m·s + 1) (τ_m = 0: none)
//   L(s) = K·G_axis(s)·H_m(s)/s with the loop gain K = 1000·Kg·kd [1/s]
//   E(s) = ΔTdr/(s·(1 + L(s))) = B(s)/A(s),  e = Tdr − Td_measured.
// With d(s) = D_axis(s)·(τ_m·s + 1) (D_axis normalised to d(0) = 1): B = ΔTdr·d(s), A = s·d(s) + K.
// Orders: first-order axis 2 (3 with τ_m), second-order axis 3 (4 with τ_m).
//
// Note: for order 2 (first-order axis, no lag) J = ΔTdr²·(τ_v/2 + 1/(2K)) falls monotonically as K
// grows, so ISE has no finite minimiser; optimal_kg() says so (kNoFiniteMinimum) rather than
// returning an arbitrary large gain.
//
// An offline tool, not a block (DESIGN §3): the library of edm-kgdesign and its test. Non-RT
// design helpers (allocate, may throw std::invalid_argument on malformed polynomials).
// Thread-safe: pure functions, no shared state.

#include <complex>
#include <span>
#include <string>
#include <vector>

namespace edm::kgdesign {

enum class AxisOrder { kFirstOrder, kSecondOrder };

/// Z axis from velocity command to velocity, unit DC gain (PLANT-MODEL §3).
struct AxisModel {
  AxisOrder order{AxisOrder::kSecondOrder};
  double tau_v_s{0.005};   // first order: velocity-loop time constant [s], > 0
  double wn_rad_s{200.0};  // second order: natural frequency [rad/s], > 0
  double zeta{0.55};       // second order: damping ratio [–], > 0
};

struct GapLoopModel {
  double kd_us_per_um{5.0 / 7.0};  // Td slope at the working gap [µs/µm], > 0
  AxisModel axis{};
  double tau_meas_s{0.0};   // first-order lag on the measured Td [s], ≥ 0 (0: none)
  double tdr_step_us{1.0};  // size of the Tdr step [µs], ≠ 0; J scales with its square
  /// Empty means valid.
  [[nodiscard]] std::vector<std::string> validate() const;
};

/// E(s) = B(s)/A(s), coefficients in ascending powers of s: b[i], a[i] multiply s^i.
struct ErrorTransfer {
  std::vector<double> b;
  std::vector<double> a;
};

/// K = 1000·Kg·kd [1/s] (the 1000 turns mm/s into µm/s).
[[nodiscard]] double loop_gain_per_s(const GapLoopModel& m, double kg_mm_s_per_us);
/// Closed-loop error transfer for a step of m.tdr_step_us in Tdr. Requires a valid model.
[[nodiscard]] ErrorTransfer error_transfer(const GapLoopModel& m, double kg_mm_s_per_us);

/// Strict Hurwitz test by the Routh array (ascending coefficients, a.back() ≠ 0): true iff all
/// roots of A have negative real parts. A zero in the first column counts as not stable.
[[nodiscard]] bool is_hurwitz(std::span<const double> a);

/// J = (1/2πj)∮ B(s)B(−s)/(A(s)A(−s)) ds = ∫₀^∞ e²(t) dt, e = L⁻¹{B/A}, for n = deg A ∈ 1…4,
/// from the closed-form table (ascending coefficients, A = a_n·sⁿ + … + a0, B of degree ≤ n−1).
/// Returns +inf when A is not strictly Hurwitz. Throws std::invalid_argument when n ∉ 1…4,
/// a_n = 0, B has n + 1 or more coefficients, or a coefficient is not finite.
[[nodiscard]] double ise_integral(std::span<const double> b, std::span<const double> a);

/// J(Kg) of the model [µs²·s]; +inf when the closed loop is unstable.
[[nodiscard]] double ise_for_kg(const GapLoopModel& m, double kg_mm_s_per_us);

/// Stability limit of Kg [(mm/s)/µs] (closed loop stable for 0 < Kg < limit); +inf if none.
[[nodiscard]] double critical_kg(const GapLoopModel& m);

/// Roots of A (ascending coefficients, degree 1…8) by Durand–Kerner iteration.
[[nodiscard]] std::vector<std::complex<double>> polynomial_roots(std::span<const double> a);

enum class KgDesignStatus {
  kOk,               // interior minimum found
  kNoFiniteMinimum,  // J keeps falling as Kg grows (order 2); kg is where the search stopped
  kInvalidModel,     // see errors
};

struct KgDesignResult {
  KgDesignStatus status{KgDesignStatus::kInvalidModel};
  double kg_mm_s_per_us{0.0};   // ISE-optimal Kg
  double loop_gain_per_s{0.0};  // K = 1000·Kg·kd
  double ise_us2_s{0.0};        // J at that Kg [µs²·s] (kNoFiniteMinimum: ≈ its infimum)
  double critical_kg{0.0};      // stability limit, +inf if none
  int order{0};                 // n = deg A
  ErrorTransfer transfer;       // B, A at the optimum
  std::vector<std::complex<double>> poles;  // closed-loop poles [rad/s]
  std::vector<std::string> errors;          // validation messages (kInvalidModel)
};

/// Minimises J(Kg) from the table: bracket by doubling/halving from a model time-scale guess,
/// then golden-section search on ln Kg to a relative width of 1e-10.
[[nodiscard]] KgDesignResult optimal_kg(const GapLoopModel& m);

}  // namespace edm::kgdesign
