#include "edm/sim/gap_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace edm::sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

GapModel::GapModel(const SimParams& p)
    : p_(p), law_(p.td_law == "quadratic" ? TdLaw::kQuadratic : TdLaw::kExp) {
  quad_vertex_um_ = p_.td_quad_a_us > 0.0 ? -p_.td_quad_b_us / (2.0 * p_.td_quad_a_us) : 0.0;
}

double GapModel::td_median_us(double gap_um, double debris) const noexcept {
  const double debris_scale = std::exp(-p_.td_debris_k * debris);
  if (law_ == TdLaw::kQuadratic) {
    if (gap_um > p_.td_quad_max_gap_um) return kInf;
    const double g = std::max(gap_um, quad_vertex_um_);
    const double tau = (p_.td_quad_a_us * g + p_.td_quad_b_us) * g + p_.td_quad_c_us;
    return std::max(p_.td_tau_min_us, tau) * debris_scale;
  }
  return p_.td_tau_min_us +
         p_.td_tau_ref_us * std::exp((gap_um - p_.td_gap_ref_um) / p_.td_len_um) * debris_scale;
}

double GapModel::td_draw_us(double median_us, double weibull_k, double u) noexcept {
  return median_us * std::pow(-std::log1p(-u) / std::numbers::ln2, 1.0 / weibull_k);
}

double GapModel::td_cdf(double t_us, double median_us, double weibull_k) noexcept {
  if (t_us <= 0.0) return 0.0;
  return 1.0 - std::exp(-std::numbers::ln2 * std::pow(t_us / median_us, weibull_k));
}

double GapModel::no_ignition_gap_um(double wait_us, double debris, double p_min) const noexcept {
  if (law_ == TdLaw::kQuadratic) return p_.td_quad_max_gap_um;
  // Median at which P(Td <= wait) = p_min, then invert τ_min + τ_r e^((g-g_r)/ℓ_g) e^(-k c).
  const double q = std::pow(-std::log1p(-p_min) / std::numbers::ln2, 1.0 / p_.weibull_k);
  const double tau = wait_us / q;
  const double core =
      (tau - p_.td_tau_min_us) / (p_.td_tau_ref_us * std::exp(-p_.td_debris_k * debris));
  return p_.td_gap_ref_um + p_.td_len_um * std::log(std::max(core, 1e-300));
}

double GapModel::debris_short_probability(double gap_um, double debris) const noexcept {
  const double c_crit =
      std::min(p_.debris_c_max, p_.debris_c0 + p_.debris_a_g_per_um * std::max(gap_um, 0.0));
  return 1.0 / (1.0 + std::exp(-p_.debris_k_s * (debris - c_crit)));
}

double GapModel::arc_probability(double t_dis_us, double debris, double gap_um) const noexcept {
  const double p = p_.arc_p0 + p_.arc_k_t * std::exp(-t_dis_us / p_.deion_us) +
                   p_.arc_k_c * debris + p_.arc_k_g * std::max(0.0, 1.0 - gap_um / p_.arc_gap_um);
  return std::clamp(p, 0.0, p_.arc_p_max);
}

PulseOutcome GapModel::classify(const PulseInput& in, const PulseDraw& d) const noexcept {
  if (in.gap_um <= p_.short_gap_um) return {PulseClass::kShort, 0.0, false};
  if (d.u_short < debris_short_probability(in.gap_um, in.debris)) {
    return {PulseClass::kShort, 0.0, true};
  }
  if (!(in.td_median_us < kInf)) return {PulseClass::kOpen, in.wait_us, false};
  const double td = td_draw_us(in.td_median_us, p_.weibull_k, d.u_td);
  if (td > in.wait_us) return {PulseClass::kOpen, in.wait_us, false};
  if (d.u_arc < arc_probability(in.t_dis_us, in.debris, in.gap_um)) {
    return {in.prev_arc ? PulseClass::kStableArc : PulseClass::kTransientArc,
            d.u_arc_td * p_.arc_td_max_us, false};
  }
  return {PulseClass::kNormal, td, false};
}

double GapModel::mean_spark_volume_mm3(double ip_a, double on_us) const noexcept {
  if (p_.crater_ref_um3 > 0.0) return p_.crater_ref_um3 * std::pow(ip_a, p_.crater_exp) * 1e-9;
  return p_.removal_mm3_per_j * p_.discharge_voltage_v * ip_a * on_us * 1e-6;
}

double GapModel::spark_volume_mm3(double ip_a, double on_us, double debris,
                                  double z) const noexcept {
  return mean_spark_volume_mm3(ip_a, on_us) * (1.0 - std::clamp(debris, 0.0, 1.0)) *
         std::max(0.0, 1.0 + p_.removal_sigma * z);
}

double GapModel::flush_rate_per_s(double gap_um, double depth_mm, double flush_eff) const noexcept {
  const double r = std::clamp(gap_um / p_.flush_gap_ref_um, 0.0, 1.0);
  const double h = depth_mm / p_.flush_depth_mm;
  return flush_eff * r * r * r / (p_.flush_tau0_ms * 1e-3 * (1.0 + h * h));
}

double GapModel::debris_after(double debris, double rate_per_s, double dt_s) const noexcept {
  return debris * std::exp(-rate_per_s * std::exp(-p_.debris_flush_k * debris) * dt_s);
}

}  // namespace edm::sim
