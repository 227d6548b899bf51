#pragma once
// Gap physics of one pulse as pure functions of (parameters, gap, debris, random draws):
// ignition-delay laws, the pulse classifier, crater volume and the debris flushing ODE
// (PLANT-MODEL.md §6.2). The Plant strings these together; tests check them one by one.
//
// RT-safety: every member function is noexcept and allocation-free; the constructor is non-RT.
// Thread-safety: immutable after construction; const calls are safe from any thread.

#include <cstdint>

#include "edm/sim/params.hpp"

namespace edm::sim {

/// Pulse classes. The five states of seed 001; seed 003 merges the arcs; seed 000 calls
/// everything but kNormal "abnormal".
enum class PulseClass : std::uint8_t { kOpen, kNormal, kTransientArc, kStableArc, kShort };

enum class TdLaw : std::uint8_t { kExp, kQuadratic };

/// What the classifier needs to know about the gap when a pulse starts.
struct PulseInput {
  double gap_um{0.0};        // smallest gap (front, or any wall bin when they compete)
  double debris{0.0};        // c in [0, 1]
  double td_median_us{0.0};  // median ignition delay; +inf when no ignition is possible
  double t_dis_us{1e9};      // time since the end of the last discharge
  double wait_us{100.0};     // T_wait
  bool prev_arc{false};      // the previous pulse was an arc
};

/// The uniforms (0, 1) one pulse consumes, each from its own stream (random.hpp).
struct PulseDraw {
  double u_short{0.5}, u_arc{0.5}, u_td{0.5}, u_arc_td{0.5};
};

struct PulseOutcome {
  PulseClass cls{PulseClass::kOpen};
  double td_us{0.0};         // delay before current flows: Td, arc delay, T_wait (open), 0
  bool debris_short{false};  // a short from a debris bridge (lasts t_bs)
};

class GapModel {
 public:
  explicit GapModel(const SimParams& p);

  /// Median ignition delay τ_med(g, c) in µs (§6.2 step 4 or the quadratic WEDM law of §1).
  /// +inf beyond the quadratic law's no-ignition gap. Below the parabola's vertex the quadratic
  /// is held at its minimum so that a smaller gap never ignites later.
  [[nodiscard]] double td_median_us(double gap_um, double debris) const noexcept;
  /// Weibull draw by the inverse CDF: Td = τ_med (-ln(1-u)/ln 2)^(1/k).
  [[nodiscard]] static double td_draw_us(double median_us, double weibull_k, double u) noexcept;
  /// P(Td <= t) = 1 - 2^(-(t/τ_med)^k).
  [[nodiscard]] static double td_cdf(double t_us, double median_us, double weibull_k) noexcept;
  /// The gap beyond which a pulse ignites within wait_us with probability below p_min: the
  /// quadratic law's cut-off, or the exp law inverted at the T_wait quantile.
  [[nodiscard]] double no_ignition_gap_um(double wait_us, double debris,
                                          double p_min = 1e-9) const noexcept;
  /// σ(k_s (c − min(c_max, c0 + a_g g))) (§6.2 step 2).
  [[nodiscard]] double debris_short_probability(double gap_um, double debris) const noexcept;
  /// clamp(p_a0 + k_t e^(−t_dis/τ_di) + k_c c + k_g max(0, 1 − g/g_a), 0, p_max) (step 3).
  [[nodiscard]] double arc_probability(double t_dis_us, double debris,
                                       double gap_um) const noexcept;
  /// Steps 1-4. Differs from the spec's order in one way: the arc draw comes after Td, and only
  /// pulses that would ignite (Td <= T_wait) can arc, since an arc needs a breakdown too.
  [[nodiscard]] PulseOutcome classify(const PulseInput& in, const PulseDraw& d) const noexcept;
  /// Mean crater volume of one normal spark, mm³: η U_d Ip t_on, or the crater law.
  [[nodiscard]] double mean_spark_volume_mm3(double ip_a, double on_us) const noexcept;
  /// V = mean (1 − c) max(0, 1 + σ_v z) (step 6; z standard normal).
  [[nodiscard]] double spark_volume_mm3(double ip_a, double on_us, double debris,
                                        double z) const noexcept;
  /// Flushing rate F min(1, (g/g_ref)³) / (τ_f0 (1 + (h/h_f)²)) in 1/s (step 7).
  [[nodiscard]] double flush_rate_per_s(double gap_um, double depth_mm,
                                        double flush_eff) const noexcept;
  /// Debris after dt of ċ = −rate e^(−k c) c, with the e^(−k c) factor frozen over dt (exact
  /// for k = 0, and unconditionally stable, so long idle steps cannot overshoot below 0).
  [[nodiscard]] double debris_after(double debris, double rate_per_s, double dt_s) const noexcept;

  [[nodiscard]] TdLaw law() const noexcept { return law_; }
  [[nodiscard]] double weibull_k() const noexcept { return p_.weibull_k; }

 private:
  SimParams p_;  // a copy: the strings are never touched after construction
  TdLaw law_{TdLaw::kExp};
  double quad_vertex_um_{0.0};
};

}  // namespace edm::sim
