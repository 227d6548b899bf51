// The Kg design of apps/kgdesign (seed 004 eq. 2-3): ISE tables, stability, the optimum, and the
// Td slope taken from the simulator's law.
#include "kg_design.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "edm/sim/gap_model.hpp"
#include "edm/sim/params.hpp"
#include "td_law.hpp"

namespace edm::kgdesign {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One classic RK4 step of x' = f(x) for a fixed-size state.
template <std::size_t N, class F>
void rk4_step(std::array<double, N>& x, double dt, const F& f) {
  std::array<double, N> k1{}, k2{}, k3{}, k4{}, tmp{};
  f(x, k1);
  for (std::size_t i = 0; i < N; ++i) tmp[i] = x[i] + 0.5 * dt * k1[i];
  f(tmp, k2);
  for (std::size_t i = 0; i < N; ++i) tmp[i] = x[i] + 0.5 * dt * k2[i];
  f(tmp, k3);
  for (std::size_t i = 0; i < N; ++i) tmp[i] = x[i] + dt * k3[i];
  f(tmp, k4);
  for (std::size_t i = 0; i < N; ++i)
    x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

// ∫ e² dt with e = L⁻¹{B/A}, by RK4 on the controllable canonical realisation of B/A: the
// impulse sets x(0+) = e_n/a_n and e = Σ b_i·x_(i+1). The last state component accumulates e².
double simulated_ise_from_polys(const std::vector<double>& b, const std::vector<double>& a,
                                double dt, double t_end) {
  const std::size_t n = a.size() - 1;
  std::array<double, 5> x{};  // x[0..n-1] the realisation, x[4] = ∫ e²
  x[n - 1] = 1.0 / a[n];
  const auto output = [&](const std::array<double, 5>& s) {
    double e = 0.0;
    for (std::size_t i = 0; i < b.size(); ++i) e += b[i] * s[i];
    return e;
  };
  const auto f = [&](const std::array<double, 5>& s, std::array<double, 5>& ds) {
    ds.fill(0.0);
    for (std::size_t i = 0; i + 1 < n; ++i) ds[i] = s[i + 1];
    double top = 0.0;
    for (std::size_t i = 0; i < n; ++i) top -= a[i] * s[i];
    ds[n - 1] = top / a[n];
    const double e = output(s);
    ds[4] = e * e;
  };
  const auto steps = static_cast<long>(std::ceil(t_end / dt));
  for (long k = 0; k < steps; ++k) rk4_step(x, dt, f);
  EXPECT_LT(std::abs(output(x)), 1e-6) << "e(t_end) should be negligible";
  return x[4];
}

// Expands Π(s − p) over the poles (complex pairs given once, conjugate implied) into ascending
// real coefficients scaled by `lead`.
std::vector<double> poly_from_poles(const std::vector<std::complex<double>>& poles, double lead) {
  std::vector<std::complex<double>> c{1.0};
  const auto mul = [&](std::complex<double> p) {
    std::vector<std::complex<double>> r(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      r[i + 1] += c[i];
      r[i] -= p * c[i];
    }
    c = r;
  };
  for (const auto& p : poles) {
    mul(p);
    if (p.imag() != 0.0) mul(std::conj(p));
  }
  std::vector<double> out;
  for (const auto& v : c) out.push_back(lead * v.real());
  return out;
}

// The closed gap loop written out as its physical ODE (not from the polynomials): states gap
// deviation [µm], axis velocity [mm/s] (and acceleration for the 2nd-order axis), measured Td
// [µs] and ∫e². Step of m.tdr_step_us in Tdr at t = 0 from rest; runs until a 50 ms chunk adds
// less than 1e-11 of the total.
double simulated_ise_of_loop(const GapLoopModel& m, double kg) {
  enum : std::size_t { kGap, kVel, kAcc, kTdMeas, kJ, kSize };
  const bool second = m.axis.order == AxisOrder::kSecondOrder;
  const double tdr = m.tdr_step_us;
  const double wn = m.axis.wn_rad_s, zeta = m.axis.zeta;
  const auto td_meas = [&](const std::array<double, kSize>& s) {
    return m.tau_meas_s > 0.0 ? s[kTdMeas] : m.kd_us_per_um * s[kGap];
  };
  const auto f = [&](const std::array<double, kSize>& s, std::array<double, kSize>& ds) {
    const double e = tdr - td_meas(s);
    const double v_cmd_mm_s = kg * e;
    ds.fill(0.0);
    ds[kGap] = 1000.0 * s[kVel];  // Z up opens the gap; mm/s → µm/s
    if (second) {
      ds[kVel] = s[kAcc];
      ds[kAcc] = wn * wn * (v_cmd_mm_s - s[kVel]) - 2.0 * zeta * wn * s[kAcc];
    } else {
      ds[kVel] = (v_cmd_mm_s - s[kVel]) / m.axis.tau_v_s;
    }
    if (m.tau_meas_s > 0.0) ds[kTdMeas] = (m.kd_us_per_um * s[kGap] - s[kTdMeas]) / m.tau_meas_s;
    ds[kJ] = e * e;
  };
  double rate = second ? wn : 1.0 / m.axis.tau_v_s;
  if (m.tau_meas_s > 0.0) rate = std::max(rate, 1.0 / m.tau_meas_s);
  rate = std::max(rate, loop_gain_per_s(m, kg));
  const double dt = 0.01 / rate;
  const auto chunk_steps = static_cast<long>(std::ceil(0.05 / dt));
  std::array<double, kSize> x{};
  for (int chunk = 0; chunk < 4000; ++chunk) {
    const double before = x[kJ];
    for (long k = 0; k < chunk_steps; ++k) rk4_step(x, dt, f);
    if (chunk >= 2 && x[kJ] - before < 1e-11 * x[kJ]) return x[kJ];
  }
  ADD_FAILURE() << "simulation did not settle (kg " << kg << ")";
  return x[kJ];
}

// Kg of the least simulated J: a 40-point log sweep over [lo, hi], then 21 points between the
// neighbours of the coarse minimum.
double brute_force_kg(const GapLoopModel& m, double lo, double hi) {
  const auto sweep = [&](double a, double b, int points, double& best_j) {
    double best = a;
    best_j = kInf;
    for (int i = 0; i < points; ++i) {
      const double kg = a * std::pow(b / a, static_cast<double>(i) / (points - 1));
      const double j = simulated_ise_of_loop(m, kg);
      if (j < best_j) {
        best_j = j;
        best = kg;
      }
    }
    return best;
  };
  double j = 0.0;
  const double coarse = sweep(lo, hi, 40, j);
  const double step = std::pow(hi / lo, 1.0 / 39.0);
  return sweep(coarse / step, coarse * step, 21, j);
}

// (a) Table formulas against numerical integration of e(t)², random stable A and random B.
TEST(KgDesignIse, table_matches_rk4_integration_of_random_stable_systems) {
  std::mt19937_64 rng(0x5eed004);
  std::uniform_real_distribution<double> sigma(0.5, 5.0), omega(0.2, 5.0), coef(-2.0, 2.0),
      lead(0.5, 3.0), log_scale(-1.0, 2.0), coin(0.0, 1.0);
  for (std::size_t n = 1; n <= 4; ++n) {
    for (int trial = 0; trial < 6; ++trial) {
      const double scale = std::pow(10.0, log_scale(rng));  // time scale of the poles [1/s]
      std::vector<std::complex<double>> poles;
      double slowest = kInf, fastest = 0.0;
      while (poles.size() < n) {
        std::size_t order = 0;
        for (const auto& p : poles) order += p.imag() != 0.0 ? 2 : 1;
        if (order == n) break;
        std::complex<double> p{-sigma(rng) * scale, 0.0};
        if (n - order >= 2 && coin(rng) < 0.5) p = {p.real(), omega(rng) * scale};
        poles.push_back(p);
        slowest = std::min(slowest, -p.real());
        fastest = std::max(fastest, std::abs(p));
      }
      const std::vector<double> a = poly_from_poles(poles, lead(rng));
      ASSERT_EQ(a.size(), n + 1);
      std::vector<double> b(n);
      for (double& c : b) c = coef(rng) * std::pow(scale, 0.5);
      if (b[0] == 0.0) b[0] = 1.0;

      const double j_table = ise_integral(b, a);
      const double j_sim = simulated_ise_from_polys(b, a, 0.002 / fastest, 60.0 / slowest);
      EXPECT_NEAR(j_table, j_sim, 0.01 * j_sim) << "n = " << n << ", trial " << trial;
    }
  }
}

TEST(KgDesignIse, order_one_and_two_match_hand_results) {
  // e = 3·e^(−2t): J = 9/4.
  EXPECT_NEAR(ise_integral(std::vector<double>{3.0}, std::vector<double>{2.0, 1.0}), 2.25, 1e-15);
  // First-order axis, no lag: J = ΔTdr²·(τ_v/2 + 1/(2K)).
  GapLoopModel m;
  m.axis.order = AxisOrder::kFirstOrder;
  m.axis.tau_v_s = 0.005;
  m.tdr_step_us = 2.0;
  const double kg = 0.2;
  const double k = loop_gain_per_s(m, kg);
  EXPECT_DOUBLE_EQ(k, 1000.0 * 0.2 * (5.0 / 7.0));
  const ErrorTransfer t = error_transfer(m, kg);
  EXPECT_EQ(t.b, (std::vector<double>{2.0, 0.01}));
  EXPECT_EQ(t.a, (std::vector<double>{k, 1.0, 0.005}));
  EXPECT_NEAR(ise_for_kg(m, kg), 4.0 * (0.0025 + 0.5 / k), 1e-15);
}

TEST(KgDesignIse, malformed_polynomials_throw) {
  const std::vector<double> a5(6, 1.0);
  EXPECT_THROW((void)ise_integral(std::vector<double>{1.0}, a5), std::invalid_argument);
  EXPECT_THROW((void)ise_integral(std::vector<double>{1.0}, std::vector<double>{1.0}),
               std::invalid_argument);
  EXPECT_THROW((void)ise_integral(std::vector<double>{1.0, 1.0}, std::vector<double>{1.0, 1.0}),
               std::invalid_argument);
  EXPECT_THROW((void)ise_integral(std::vector<double>{1.0}, std::vector<double>{1.0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW((void)ise_integral(std::vector<double>{std::nan("")}, std::vector<double>{1.0, 1.0}),
               std::invalid_argument);
}

// (c) Unstable or marginal A → +inf.
TEST(KgDesignStability, unstable_polynomials_give_infinite_ise) {
  const std::vector<double> b{1.0};
  EXPECT_EQ(ise_integral(b, std::vector<double>{-1.0, 1.0}), kInf);           // s − 1
  EXPECT_EQ(ise_integral(b, std::vector<double>{0.0, 1.0}), kInf);            // pole at 0
  EXPECT_EQ(ise_integral(b, std::vector<double>{1.0, 0.0, 1.0}), kInf);       // ±j
  EXPECT_EQ(ise_integral(b, std::vector<double>{1.0, -0.1, 1.0}), kInf);      // RHP pair
  EXPECT_EQ(ise_integral(b, std::vector<double>{7.0, 1.0, 1.0, 1.0}), kInf);  // a1a2 < a0a3
  EXPECT_EQ(ise_integral(b, std::vector<double>{1.0, 1.0, 1.0, 1.0}), kInf);  // a1a2 = a0a3
  // (s² + 0.1s + 4)(s² − 0.1s + 1): all but one coefficient positive, one RHP pair.
  EXPECT_EQ(ise_integral(b, poly_from_poles({{-0.05, 1.998}, {0.05, 0.9987}}, 1.0)), kInf);
  // (s + 1)⁴ positive coefficients, stable; (s² + s + 1)(s² + 0.01 s + 9) nearly marginal.
  EXPECT_TRUE(
      std::isfinite(ise_integral(b, poly_from_poles({{-1, 0}, {-1, 0}, {-1, 0}, {-1, 0}}, 1))));
  EXPECT_FALSE(is_hurwitz(poly_from_poles({{-0.5, 0.866}, {0.005, 3.0}}, 1.0)));
  EXPECT_TRUE(is_hurwitz(poly_from_poles({{-0.5, 0.866}, {-0.005, 3.0}}, 1.0)));
  // A negative leading coefficient is the same polynomial up to sign.
  EXPECT_TRUE(is_hurwitz(std::vector<double>{-2.0, -3.0, -1.0}));
}

TEST(KgDesignStability, hurwitz_test_agrees_with_the_roots) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> coef(-1.0, 3.0);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t n = 1 + static_cast<std::size_t>(trial % 4);
    std::vector<double> a(n + 1);
    for (double& c : a) c = coef(rng);
    a[n] = 1.0;
    const auto roots = polynomial_roots(a);
    const double max_re = std::max_element(roots.begin(), roots.end(), [](auto x, auto y) {
                            return x.real() < y.real();
                          })->real();
    if (std::abs(max_re) < 1e-6) continue;  // too close to the axis to judge from the roots
    EXPECT_EQ(is_hurwitz(a), max_re < 0.0) << "trial " << trial;
  }
}

TEST(KgDesignStability, loop_gain_beyond_the_critical_kg_gives_infinite_ise) {
  GapLoopModel m;  // 2nd-order axis, ω_n 200 rad/s, ζ 0.55: K_crit = 2ζω_n = 220 1/s
  EXPECT_NEAR(loop_gain_per_s(m, critical_kg(m)), 220.0, 1e-9);
  EXPECT_TRUE(std::isfinite(ise_for_kg(m, 0.99 * critical_kg(m))));
  EXPECT_EQ(ise_for_kg(m, 1.01 * critical_kg(m)), kInf);
  EXPECT_EQ(ise_for_kg(m, -0.1), kInf);  // positive feedback
  m.tau_meas_s = 0.001;                  // n = 4
  EXPECT_TRUE(std::isfinite(ise_for_kg(m, 0.99 * critical_kg(m))));
  EXPECT_EQ(ise_for_kg(m, 1.01 * critical_kg(m)), kInf);
  m.axis.order = AxisOrder::kFirstOrder;  // n = 3: K_crit = (τ_v + τ_m)/(τ_v·τ_m)
  EXPECT_NEAR(loop_gain_per_s(m, critical_kg(m)), 0.006 / 5e-6, 1e-6);
  EXPECT_EQ(ise_for_kg(m, 1.01 * critical_kg(m)), kInf);
  m.tau_meas_s = 0.0;  // n = 2: stable for every K > 0
  EXPECT_EQ(critical_kg(m), kInf);
}

// (b) The table optimum against a brute-force sweep of simulated J.
struct OptimumCase {
  const char* name;
  GapLoopModel model;
  int order;
};

// Names the case in gtest output (and in the ctest names) instead of a byte dump.
void PrintTo(const OptimumCase& c, std::ostream* os) { *os << c.name; }

class KgDesignOptimum : public ::testing::TestWithParam<OptimumCase> {};

TEST_P(KgDesignOptimum, table_optimum_matches_simulated_sweep) {
  const auto& c = GetParam();
  const KgDesignResult r = optimal_kg(c.model);
  ASSERT_EQ(r.status, KgDesignStatus::kOk);
  EXPECT_EQ(r.order, c.order);
  ASSERT_TRUE(std::isfinite(r.critical_kg));
  EXPECT_LT(r.kg_mm_s_per_us, r.critical_kg);
  for (const auto& p : r.poles) EXPECT_LT(p.real(), 0.0);

  const double kg_sweep = brute_force_kg(c.model, 0.02 * r.critical_kg, 0.95 * r.critical_kg);
  EXPECT_NEAR(r.kg_mm_s_per_us, kg_sweep, 0.10 * kg_sweep);
  // J of the table and of the simulation agree at the optimum too.
  const double j_sim = simulated_ise_of_loop(c.model, r.kg_mm_s_per_us);
  EXPECT_NEAR(r.ise_us2_s, j_sim, 0.01 * j_sim);
}

GapLoopModel make_model(AxisOrder order, double tau_meas_s, double kd, double tdr) {
  GapLoopModel m;
  m.axis.order = order;
  m.tau_meas_s = tau_meas_s;
  m.kd_us_per_um = kd;
  m.tdr_step_us = tdr;
  return m;
}

std::string case_name(const ::testing::TestParamInfo<OptimumCase>& p) { return p.param.name; }

INSTANTIATE_TEST_SUITE_P(
    KgDesignAxisModels, KgDesignOptimum,
    ::testing::Values(OptimumCase{"second_order_axis",
                                  make_model(AxisOrder::kSecondOrder, 0.0, 5.0 / 7.0, 1.0), 3},
                      OptimumCase{"second_order_axis_with_td_lag",
                                  make_model(AxisOrder::kSecondOrder, 0.001, 5.0 / 7.0, 2.0), 4},
                      OptimumCase{"first_order_axis_with_td_lag",
                                  make_model(AxisOrder::kFirstOrder, 0.001, 5.0 / 7.0, 1.0), 3},
                      OptimumCase{
                          "first_order_axis_sink_slope",
                          make_model(AxisOrder::kFirstOrder, 0.002,
                                     td_gap_slope_us_per_um(TdMedianLaw::sink(), 40.0), 5.0),
                          3}),
    case_name);

TEST(KgDesignOptimumOrderTwo, first_order_axis_without_lag_has_no_finite_minimum) {
  const GapLoopModel m = make_model(AxisOrder::kFirstOrder, 0.0, 5.0 / 7.0, 1.0);
  const KgDesignResult r = optimal_kg(m);
  EXPECT_EQ(r.status, KgDesignStatus::kNoFiniteMinimum);
  EXPECT_EQ(r.order, 2);
  EXPECT_NEAR(r.ise_us2_s, m.axis.tau_v_s / 2.0, 1e-9);  // the infimum τ_v/2
  // The simulation agrees: J keeps falling over two decades of Kg.
  double previous = kInf;
  for (const double kg : {0.01, 0.03, 0.1, 0.3, 1.0}) {
    const double j = simulated_ise_of_loop(m, kg);
    EXPECT_LT(j, previous) << "kg " << kg;
    EXPECT_NEAR(j, ise_for_kg(m, kg), 0.01 * j);
    previous = j;
  }
}

TEST(KgDesignOptimumOrderTwo, invalid_model_is_reported) {
  GapLoopModel m;
  m.kd_us_per_um = -1.0;
  m.axis.zeta = 0.0;
  const KgDesignResult r = optimal_kg(m);
  EXPECT_EQ(r.status, KgDesignStatus::kInvalidModel);
  EXPECT_EQ(r.errors.size(), 2u);
}

// (d) The Td law is the simulator's, and kd is its slope: against the closed forms of the exp law
// (drill, sink) and of the wire preset's quadratic law, written out here as an independent check.
TEST(KgDesignSlope, td_law_is_the_simulators_gap_model) {
  for (TdMedianLaw law : {TdMedianLaw::drill(), TdMedianLaw::sink()}) {
    law.debris = 0.3;
    const sim::GapModel model(law.params);
    for (double g = 2.0; g <= 60.0; g += 3.5) {
      EXPECT_EQ(td_median_us(law, g), model.td_median_us(g, 0.3)) << "g " << g;
    }
  }
  EXPECT_EQ(TdMedianLaw::drill().params.td_gap_ref_um,
            sim::SimParams::preset("drill")->td_gap_ref_um);
  EXPECT_EQ(TdMedianLaw::sink().params.td_len_um, sim::SimParams::preset("sink")->td_len_um);
}

TEST(KgDesignSlope, kd_matches_the_closed_form_slope_of_the_exp_law) {
  for (TdMedianLaw law : {TdMedianLaw::drill(), TdMedianLaw::sink()}) {
    for (const double debris : {0.0, 0.3}) {
      law.debris = debris;
      EXPECT_TRUE(law.validate().empty());
      const sim::SimParams& p = law.params;
      for (double g = 2.0; g <= 60.0; g += 3.5) {
        const double exact = p.td_tau_ref_us / p.td_len_um *
                             std::exp((g - p.td_gap_ref_um) / p.td_len_um) *
                             std::exp(-p.td_debris_k * debris);
        EXPECT_NEAR(td_gap_slope_us_per_um(law, g), exact, 1e-11 * exact) << "g " << g;
      }
    }
  }
  // At the reference gap of the DRILL law: τ_med = τ_min + τ_r, kd = τ_r/ℓ_g.
  EXPECT_DOUBLE_EQ(td_median_us(TdMedianLaw::drill(), 20.0), 5.5);
  EXPECT_NEAR(td_gap_slope_us_per_um(TdMedianLaw::drill(), 20.0), 5.0 / 7.0, 1e-12);
}

TEST(KgDesignSlope, kd_follows_the_wire_presets_quadratic_law) {
  TdMedianLaw law{*sim::SimParams::preset("wire"), 0.0};
  ASSERT_TRUE(law.validate().empty());
  const sim::SimParams& p = law.params;
  for (const double g : {6.0, 10.0, 15.0, 20.0}) {  // above the vertex, below the cut-off
    EXPECT_NEAR(td_gap_slope_us_per_um(law, g), 2.0 * p.td_quad_a_us * g + p.td_quad_b_us, 1e-10)
        << "g " << g;
  }
}

TEST(KgDesignSlope, debris_outside_zero_to_one_is_reported) {
  TdMedianLaw law = TdMedianLaw::drill();
  law.debris = 1.5;
  const auto errs = law.validate();
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs.front(), "debris must be in [0, 1]");
}

TEST(KgDesignSlope, polynomial_roots_recover_known_poles) {
  const auto roots =
      polynomial_roots(poly_from_poles({{-1.0, 0.0}, {-2.0, 3.0}, {-40.0, 0.0}}, 2.5));
  ASSERT_EQ(roots.size(), 4u);
  const std::vector<std::complex<double>> want{
      {-1.0, 0.0}, {-2.0, 3.0}, {-2.0, -3.0}, {-40.0, 0.0}};
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_NEAR(roots[i].real(), want[i].real(), 1e-9);
    EXPECT_NEAR(roots[i].imag(), want[i].imag(), 1e-9);
  }
}

}  // namespace
}  // namespace edm::kgdesign
