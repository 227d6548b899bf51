#include "kg_design.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace edm::kgdesign {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kUmPerMm = 1000.0;

bool finite_positive(double x) { return std::isfinite(x) && x > 0.0; }

// Multiplies two polynomials in ascending powers.
std::vector<double> poly_mul(const std::vector<double>& p, const std::vector<double>& q) {
  std::vector<double> r(p.size() + q.size() - 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < q.size(); ++j) {
      r[i + j] += p[i] * q[j];
    }
  }
  return r;
}

// d(s) = D_axis(s)·(τ_m·s + 1), normalised so d(0) = 1.
std::vector<double> loop_denominator(const GapLoopModel& m) {
  std::vector<double> d;
  if (m.axis.order == AxisOrder::kFirstOrder) {
    d = {1.0, m.axis.tau_v_s};
  } else {
    const double wn = m.axis.wn_rad_s;
    d = {1.0, 2.0 * m.axis.zeta / wn, 1.0 / (wn * wn)};
  }
  if (m.tau_meas_s > 0.0) {
    d = poly_mul(d, {1.0, m.tau_meas_s});
  }
  return d;
}

// Stability limit of the loop gain K for A = s·d(s) + K, from the Hurwitz determinants.
double critical_loop_gain(const std::vector<double>& d) {
  switch (d.size()) {
    case 3: {  // n = 3: a1·a2 > a0·a3
      return d[0] * d[1] / d[2];
    }
    case 4: {  // n = 4: a1·a2·a3 − a0·a3² − a1²·a4 > 0
      const double a1 = d[0], a2 = d[1], a3 = d[2], a4 = d[3];
      return std::max(0.0, (a1 * a2 * a3 - a1 * a1 * a4) / (a3 * a3));
    }
    default:  // n = 2 (and n = 1): stable for every K > 0
      return kInf;
  }
}

}  // namespace

std::vector<std::string> GapLoopModel::validate() const {
  std::vector<std::string> errs;
  if (!finite_positive(kd_us_per_um)) errs.emplace_back("kd_us_per_um must be > 0");
  if (axis.order == AxisOrder::kFirstOrder) {
    if (!finite_positive(axis.tau_v_s)) errs.emplace_back("axis.tau_v_s must be > 0");
  } else {
    if (!finite_positive(axis.wn_rad_s)) errs.emplace_back("axis.wn_rad_s must be > 0");
    if (!finite_positive(axis.zeta)) errs.emplace_back("axis.zeta must be > 0");
  }
  if (!std::isfinite(tau_meas_s) || tau_meas_s < 0.0) errs.emplace_back("tau_meas_s must be >= 0");
  if (!std::isfinite(tdr_step_us) || tdr_step_us == 0.0) {
    errs.emplace_back("tdr_step_us must be finite and non-zero");
  }
  return errs;
}

double loop_gain_per_s(const GapLoopModel& m, double kg_mm_s_per_us) {
  return kUmPerMm * kg_mm_s_per_us * m.kd_us_per_um;
}

ErrorTransfer error_transfer(const GapLoopModel& m, double kg_mm_s_per_us) {
  const std::vector<double> d = loop_denominator(m);
  ErrorTransfer t;
  t.b.reserve(d.size());
  for (const double c : d) t.b.push_back(m.tdr_step_us * c);
  t.a.reserve(d.size() + 1);
  t.a.push_back(loop_gain_per_s(m, kg_mm_s_per_us));  // A = s·d(s) + K
  t.a.insert(t.a.end(), d.begin(), d.end());
  return t;
}

bool is_hurwitz(std::span<const double> a) {
  if (a.empty() || a.back() == 0.0) return false;
  const std::size_t n = a.size() - 1;
  const double sign = a.back() > 0.0 ? 1.0 : -1.0;
  // Routh rows hold the coefficients of s^n, s^(n−2), … and s^(n−1), s^(n−3), …
  std::vector<double> prev, cur;
  for (std::size_t k = 0; k <= n; k += 2) prev.push_back(sign * a[n - k]);
  for (std::size_t k = 1; k <= n; k += 2) cur.push_back(sign * a[n - k]);
  if (!(prev[0] > 0.0)) return false;
  for (std::size_t row = 1; row <= n; ++row) {
    if (cur.empty() || !(cur[0] > 0.0)) return false;
    std::vector<double> next;
    for (std::size_t k = 0; k + 1 < prev.size(); ++k) {
      const double c = k + 1 < cur.size() ? cur[k + 1] : 0.0;
      next.push_back((cur[0] * prev[k + 1] - prev[0] * c) / cur[0]);
    }
    prev = std::move(cur);
    cur = std::move(next);
  }
  return true;
}

double ise_integral(std::span<const double> b_in, std::span<const double> a_in) {
  if (a_in.size() < 2 || a_in.size() > 5) {
    throw std::invalid_argument("ise_integral: deg A must be 1..4");
  }
  const std::size_t n = a_in.size() - 1;
  if (b_in.size() > n) throw std::invalid_argument("ise_integral: deg B must be < deg A");
  const auto all_finite = [](std::span<const double> v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (!all_finite(a_in) || !all_finite(b_in)) {
    throw std::invalid_argument("ise_integral: coefficients must be finite");
  }
  if (a_in.back() == 0.0) throw std::invalid_argument("ise_integral: a_n must be non-zero");
  if (!is_hurwitz(a_in)) return kInf;

  // Dividing B and A by a_n leaves E = B/A unchanged and keeps the products well scaled.
  std::array<double, 5> a{};
  std::array<double, 4> b{};
  for (std::size_t i = 0; i <= n; ++i) a[i] = a_in[i] / a_in[n];
  for (std::size_t i = 0; i < b_in.size(); ++i) b[i] = b_in[i] / a_in[n];

  switch (n) {
    case 1: return b[0] * b[0] / (2.0 * a[0] * a[1]);
    case 2: return (b[1] * b[1] * a[0] + b[0] * b[0] * a[2]) / (2.0 * a[0] * a[1] * a[2]);
    case 3: {
      const double num = b[2] * b[2] * a[0] * a[1] +
                         (b[1] * b[1] - 2.0 * b[0] * b[2]) * a[0] * a[3] +
                         b[0] * b[0] * a[2] * a[3];
      return num / (2.0 * a[0] * a[3] * (a[1] * a[2] - a[0] * a[3]));
    }
    default: {  // n = 4
      const double num = b[3] * b[3] * (a[0] * a[1] * a[2] - a[0] * a[0] * a[3]) +
                         (b[2] * b[2] - 2.0 * b[1] * b[3]) * a[0] * a[1] * a[4] +
                         (b[1] * b[1] - 2.0 * b[0] * b[2]) * a[0] * a[3] * a[4] +
                         b[0] * b[0] * (a[2] * a[3] * a[4] - a[1] * a[4] * a[4]);
      const double den =
          2.0 * a[0] * a[4] * (a[1] * a[2] * a[3] - a[0] * a[3] * a[3] - a[1] * a[1] * a[4]);
      return num / den;
    }
  }
}

double ise_for_kg(const GapLoopModel& m, double kg_mm_s_per_us) {
  const ErrorTransfer t = error_transfer(m, kg_mm_s_per_us);
  return ise_integral(t.b, t.a);
}

double critical_kg(const GapLoopModel& m) {
  return critical_loop_gain(loop_denominator(m)) / (kUmPerMm * m.kd_us_per_um);
}

std::vector<std::complex<double>> polynomial_roots(std::span<const double> a) {
  if (a.size() < 2 || a.size() > 9 || a.back() == 0.0) {
    throw std::invalid_argument("polynomial_roots: degree must be 1..8 with a_n != 0");
  }
  const std::size_t n = a.size() - 1;
  std::vector<double> monic(a.begin(), a.end());
  for (double& c : monic) c /= a[n];
  const auto eval = [&](std::complex<double> s) {
    std::complex<double> v = monic[n];
    for (std::size_t i = n; i-- > 0;) v = v * s + monic[i];
    return v;
  };
  // Cauchy bound on the root moduli sets the radius of the starting circle.
  double radius = 0.0;
  for (std::size_t i = 0; i < n; ++i) radius = std::max(radius, std::abs(monic[i]));
  radius += 1.0;
  std::vector<std::complex<double>> z(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double phi = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    z[k] = std::polar(radius, phi + 0.4);  // off-axis start avoids symmetric stalls
  }
  for (int iter = 0; iter < 2000; ++iter) {
    double change = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      std::complex<double> den = 1.0;
      for (std::size_t j = 0; j < n; ++j) {
        if (j != k) den *= z[k] - z[j];
      }
      if (den == 0.0) den = 1e-300;
      const std::complex<double> step = eval(z[k]) / den;
      z[k] -= step;
      change = std::max(change, std::abs(step) / (1.0 + std::abs(z[k])));
    }
    if (change < 1e-15) break;
  }
  for (auto& r : z) {
    if (std::abs(r.imag()) <= 1e-9 * std::abs(r)) r = {r.real(), 0.0};
  }
  std::sort(z.begin(), z.end(), [](const auto& x, const auto& y) {
    return x.real() != y.real() ? x.real() > y.real() : x.imag() > y.imag();
  });
  return z;
}

KgDesignResult optimal_kg(const GapLoopModel& m) {
  KgDesignResult r;
  r.errors = m.validate();
  if (!r.errors.empty()) {
    r.status = KgDesignStatus::kInvalidModel;
    return r;
  }
  r.critical_kg = critical_kg(m);
  const auto j_of = [&](double kg) { return ise_for_kg(m, kg); };

  // Start half-way to the stability limit, or at K = 1/(sum of the loop's time constants).
  const double t_sum =
      (m.axis.order == AxisOrder::kFirstOrder ? m.axis.tau_v_s
                                              : 2.0 * m.axis.zeta / m.axis.wn_rad_s) +
      m.tau_meas_s;
  const double k_per_kg = kUmPerMm * m.kd_us_per_um;
  double mid = std::isfinite(r.critical_kg) ? 0.5 * r.critical_kg : 1.0 / (t_sum * k_per_kg);
  double f_mid = j_of(mid);
  double lo = 0.0;
  double hi = 2.0 * mid;
  double f_hi = j_of(hi);
  bool bracketed = false;
  constexpr int kMaxExpansions = 64;
  if (f_hi < f_mid) {  // the minimum lies above: double until J rises
    for (int i = 0; i < kMaxExpansions; ++i) {
      lo = mid;
      mid = hi;
      f_mid = f_hi;
      hi = 2.0 * mid;
      f_hi = j_of(hi);
      if (f_hi > f_mid) {
        bracketed = true;
        break;
      }
      // J flat to rounding while still falling: no finite minimiser (order 2 tends to τ_v/2).
      if (!(f_hi < f_mid * (1.0 - 1e-13))) break;
    }
  } else {  // J(hi) ≥ J(mid) (or both +inf): halve until J rises below
    lo = 0.5 * mid;
    double f_lo = j_of(lo);
    for (int i = 0; i < kMaxExpansions; ++i) {
      if (f_lo > f_mid) {
        bracketed = true;
        break;
      }
      hi = mid;
      mid = lo;
      f_mid = f_lo;
      lo = 0.5 * mid;
      f_lo = j_of(lo);
    }
  }

  double kg = mid;
  if (bracketed) {
    // Golden-section search on u = ln Kg; J is unimodal on the stable interval.
    const double inv_phi = (std::sqrt(5.0) - 1.0) / 2.0;
    double u_a = std::log(lo), u_b = std::log(hi);
    double u_c = u_b - inv_phi * (u_b - u_a);
    double u_d = u_a + inv_phi * (u_b - u_a);
    double f_c = j_of(std::exp(u_c));
    double f_d = j_of(std::exp(u_d));
    while (u_b - u_a > 1e-10) {
      if (f_c < f_d) {
        u_b = u_d;
        u_d = u_c;
        f_d = f_c;
        u_c = u_b - inv_phi * (u_b - u_a);
        f_c = j_of(std::exp(u_c));
      } else {
        u_a = u_c;
        u_c = u_d;
        f_c = f_d;
        u_d = u_a + inv_phi * (u_b - u_a);
        f_d = j_of(std::exp(u_d));
      }
    }
    kg = std::exp(0.5 * (u_a + u_b));
    r.status = KgDesignStatus::kOk;
  } else {
    r.status = KgDesignStatus::kNoFiniteMinimum;
  }
  r.kg_mm_s_per_us = kg;
  r.loop_gain_per_s = loop_gain_per_s(m, kg);
  r.ise_us2_s = j_of(kg);
  r.transfer = error_transfer(m, kg);
  r.order = static_cast<int>(r.transfer.a.size()) - 1;
  r.poles = polynomial_roots(r.transfer.a);
  return r;
}

}  // namespace edm::kgdesign
