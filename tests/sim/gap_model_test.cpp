#include "edm/sim/gap_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "edm/sim/random.hpp"

namespace edm::sim {
namespace {

// Kolmogorov–Smirnov statistic of draws against an analytic CDF.
double ks_statistic(std::vector<double> x, const std::function<double(double)>& cdf) {
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = cdf(x[i]);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

std::vector<double> draw_td(const GapModel& m, double gap_um, double c, std::uint64_t seed) {
  constexpr int kN = 100000;
  std::vector<double> x(kN);
  const double median = m.td_median_us(gap_um, c);
  for (int i = 0; i < kN; ++i) {
    x[static_cast<std::size_t>(i)] = GapModel::td_draw_us(
        median, m.weibull_k(), uniform(seed, Stream::kTd, static_cast<std::uint64_t>(i)));
  }
  return x;
}

constexpr double kKsCritical = 1.36 / 316.227766;  // 5 % level, n = 1e5

TEST(SimGapModel, drill_exp_law_td_matches_analytic_cdf) {
  const GapModel m(*SimParams::preset("drill"));
  std::uint64_t seed = 11;
  for (double gap : {10.0, 20.0, 26.0, 35.0}) {
    for (double c : {0.0, 0.3}) {
      // Written out independently of the model: τ = 0.5 + 5 e^((g-20)/7) e^(-2c), exponential.
      const double tau = 0.5 + 5.0 * std::exp((gap - 20.0) / 7.0) * std::exp(-2.0 * c);
      EXPECT_NEAR(m.td_median_us(gap, c), tau, 1e-9 * tau);
      const auto cdf = [tau](double t) { return 1.0 - std::pow(2.0, -t / tau); };
      EXPECT_LT(ks_statistic(draw_td(m, gap, c, seed++), cdf), kKsCritical) << gap << " " << c;
    }
  }
}

TEST(SimGapModel, wedm_quadratic_law_medians_and_distribution) {
  const GapModel m(*SimParams::preset("wire"));
  // PLANT-MODEL.md §1: 7.6, 25, 67, 132 and 222 µs at 5..25 µm.
  const double expect[] = {7.6, 25.0, 67.0, 132.0, 222.0};
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(m.td_median_us(5.0 * (i + 1), 0.0), expect[i], 0.01 * expect[i]);
  }
  EXPECT_FALSE(std::isfinite(m.td_median_us(25.01, 0.0)));  // no ignition beyond 25 µm
  EXPECT_NEAR(m.td_median_us(1.0, 0.0), m.td_median_us(3.84375, 0.0), 1e-9);  // held at vertex
  std::uint64_t seed = 99;
  for (double gap : {5.0, 10.0, 15.0, 20.0}) {
    const double tau = 0.48 * gap * gap - 3.69 * gap + 14.05;
    const auto cdf = [tau](double t) { return 1.0 - std::exp(-std::log(2.0) * t / tau); };
    EXPECT_LT(ks_statistic(draw_td(m, gap, 0.0, seed++), cdf), kKsCritical) << gap;
  }
}

TEST(SimGapModel, weibull_shape_is_honoured) {
  auto p = *SimParams::preset("drill");
  p.weibull_k = 2.5;
  const GapModel m(p);
  const double tau = m.td_median_us(20.0, 0.0);
  const auto cdf = [tau](double t) {
    return 1.0 - std::exp(-std::log(2.0) * std::pow(t / tau, 2.5));
  };
  EXPECT_LT(ks_statistic(draw_td(m, 20.0, 0.0, 5), cdf), kKsCritical);
  // ...and a wrong shape is rejected by the same test (the KS test has teeth).
  const auto cdf_k1 = [tau](double t) { return 1.0 - std::pow(2.0, -t / tau); };
  EXPECT_GT(ks_statistic(draw_td(m, 20.0, 0.0, 5), cdf_k1), 10 * kKsCritical);
}

TEST(SimGapModel, no_ignition_gap) {
  const GapModel wedm(*SimParams::preset("wire"));
  EXPECT_DOUBLE_EQ(wedm.no_ignition_gap_um(250.0, 0.0), 25.0);
  const GapModel drill(*SimParams::preset("drill"));
  const double g = drill.no_ignition_gap_um(100.0, 0.0, 1e-9);
  EXPECT_GT(g, 100.0);
  EXPECT_LT(g, 250.0);
  EXPECT_NEAR(GapModel::td_cdf(100.0, drill.td_median_us(g, 0.0), 1.0), 1e-9, 1e-11);
}

TEST(SimGapModel, classifier_steps) {
  const GapModel m(*SimParams::preset("drill"));
  PulseInput in;
  in.debris = 0.0;
  in.t_dis_us = 1e6;
  in.wait_us = 100.0;
  PulseDraw d;
  // 1. hard short at or below g_c, whatever the draws.
  in.gap_um = 2.0;
  in.td_median_us = m.td_median_us(in.gap_um, 0.0);
  EXPECT_EQ(m.classify(in, d).cls, PulseClass::kShort);
  // 2. debris short: c well above c_crit(20 µm) = 0.7.
  in.gap_um = 20.0;
  in.debris = 0.8;
  in.td_median_us = m.td_median_us(in.gap_um, in.debris);
  d.u_short = 0.99;
  auto out = m.classify(in, d);
  EXPECT_EQ(out.cls, PulseClass::kShort);
  EXPECT_TRUE(out.debris_short);
  EXPECT_NEAR(m.debris_short_probability(20.0, 0.7), 0.5, 1e-12);
  // 3./4. open when Td > T_wait; an open pulse never arcs.
  in.debris = 0.0;
  in.td_median_us = m.td_median_us(in.gap_um, 0.0);
  d = {};
  d.u_td = 1.0 - 1e-12;
  d.u_arc = 0.0;
  EXPECT_EQ(m.classify(in, d).cls, PulseClass::kOpen);
  // arc (delay in [0, 0.5) µs), stable after an arc.
  d.u_td = 0.5;
  d.u_arc = 0.001;
  d.u_arc_td = 0.5;
  out = m.classify(in, d);
  EXPECT_EQ(out.cls, PulseClass::kTransientArc);
  EXPECT_DOUBLE_EQ(out.td_us, 0.25);
  in.prev_arc = true;
  EXPECT_EQ(m.classify(in, d).cls, PulseClass::kStableArc);
  // normal with Td = median at u = 0.5.
  d.u_arc = 0.5;
  out = m.classify(in, d);
  EXPECT_EQ(out.cls, PulseClass::kNormal);
  EXPECT_NEAR(out.td_us, in.td_median_us, 1e-9);
}

TEST(SimGapModel, arc_probability_terms) {
  const GapModel m(*SimParams::preset("drill"));
  EXPECT_NEAR(m.arc_probability(1e9, 0.0, 100.0), 0.01, 1e-12);
  EXPECT_NEAR(m.arc_probability(6.0, 0.0, 100.0), 0.01 + 0.3 / std::exp(1.0), 1e-12);
  EXPECT_NEAR(m.arc_probability(1e9, 0.5, 100.0), 0.16, 1e-12);
  EXPECT_NEAR(m.arc_probability(1e9, 0.0, 2.5), 0.16, 1e-12);
  EXPECT_DOUBLE_EQ(m.arc_probability(0.0, 1.0, 0.0), 0.9);
}

TEST(SimGapModel, spark_volume_and_scatter) {
  const GapModel m(*SimParams::preset("drill"));
  // 25 V x 15 A x 20 µs = 7.5 mJ; x 3.2e-3 mm³/J.
  EXPECT_NEAR(m.mean_spark_volume_mm3(15.0, 20.0), 2.4e-5, 1e-12);
  EXPECT_NEAR(m.spark_volume_mm3(15.0, 20.0, 0.25, 0.0), 0.75 * 2.4e-5, 1e-12);
  EXPECT_DOUBLE_EQ(m.spark_volume_mm3(15.0, 20.0, 0.0, -6.0), 0.0);  // clipped at 0
  double sum = 0.0, sum2 = 0.0;
  constexpr int kN = 50000;
  for (int i = 0; i < kN; ++i) {
    const double v =
        m.spark_volume_mm3(15.0, 20.0, 0.0, normal(1, Stream::kRemovalScatter, std::uint64_t(i))) /
        2.4e-5;
    sum += v;
    sum2 += v * v;
  }
  EXPECT_NEAR(sum / kN, 1.0, 0.005);
  EXPECT_NEAR(std::sqrt(sum2 / kN - (sum / kN) * (sum / kN)), 0.2, 0.005);
  // WEDM crater law: SPARC's table at 1 A and 17 A.
  const GapModel w(*SimParams::preset("wire"));
  EXPECT_NEAR(w.mean_spark_volume_mm3(1.0, 3.0), 2.2e-6, 1e-12);
  EXPECT_NEAR(w.mean_spark_volume_mm3(17.0, 3.0), 6e-5, 0.03 * 6e-5);
}

TEST(SimGapModel, flushing_law) {
  const GapModel m(*SimParams::preset("drill"));
  EXPECT_NEAR(m.flush_rate_per_s(25.0, 0.0, 1.0), 200.0, 1e-9);        // 1 / 5 ms
  EXPECT_NEAR(m.flush_rate_per_s(50.0, 15.0, 1.0), 20.0, 1e-9);        // (1 + 9)
  EXPECT_NEAR(m.flush_rate_per_s(12.5, 0.0, 1.0), 200.0 / 8.0, 1e-9);  // (g/g_ref)³
  EXPECT_NEAR(m.flush_rate_per_s(25.0, 0.0, 0.3), 60.0, 1e-9);
  // c' = -r e^{-c} c over a short step.
  const double c1 = m.debris_after(0.4, 20.0, 1e-4);
  EXPECT_NEAR((0.4 - c1) / 1e-4, 20.0 * std::exp(-0.4) * 0.4, 0.01);
  const double c_big_step = m.debris_after(0.4, 20.0, 100.0);  // stable for huge steps
  EXPECT_GE(c_big_step, 0.0);
  EXPECT_LT(c_big_step, 1e-6);
}

}  // namespace
}  // namespace edm::sim
