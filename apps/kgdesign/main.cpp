// edm-kgdesign — the ISE-optimal gain of the P gap controller Vz = Kg·(Tdr − Td) (SEEDS 004
// eq. 1–3) for a linearised gap + Z-axis model, its Td slope from the simulator's law; see
// kg_design.hpp, td_law.hpp and docs/blocks.md.
// Exit codes: 0 ok, 2 bad arguments or invalid model.

#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "edm/apps/cli.hpp"
#include "kg_design.hpp"
#include "td_law.hpp"

namespace {

using edm::kgdesign::AxisOrder;
using edm::kgdesign::GapLoopModel;
using edm::kgdesign::KgDesignStatus;
using edm::kgdesign::TdMedianLaw;

constexpr const char* kUsage =
    "edm-kgdesign [--law drill|sink] [--gap-um G] [--debris C] [--kd-us-per-um K]\n"
    "                    [--tau-v-ms T | --wn W --zeta Z] [--tau-m-ms T] [--tdr-us D] [--kg KG]";

int bad(const std::string& msg) {
  std::fprintf(stderr, "edm-kgdesign: %s\nusage: %s\n", msg.c_str(), kUsage);
  return edm::apps::kExitBadInput;
}

std::string format_poly(std::span<const double> p) {
  std::string out = "[";
  char buf[64];
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.6g", i == 0 ? "" : ", ", p[i]);
    out += buf;
  }
  return out + "]";
}

void print_poles(const std::vector<std::complex<double>>& poles) {
  for (const auto& p : poles) {
    if (p.imag() < 0.0) continue;  // print each conjugate pair once
    const double wn = std::abs(p);
    if (p.imag() == 0.0) {
      std::printf("  pole            %.6g rad/s (real, time constant %.4g ms)\n", p.real(),
                  -1e3 / p.real());
    } else {
      std::printf("  pole            %.6g +/- %.6gj rad/s (wn %.4g rad/s, zeta %.4f)\n", p.real(),
                  p.imag(), wn, -p.real() / wn);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  TdMedianLaw law = TdMedianLaw::drill();
  std::string law_name = "drill";
  std::optional<double> gap_um, debris, kd, tau_v_ms, wn, zeta, tau_m_ms, tdr_us, kg_eval;

  CLI::App app(
      "edm-kgdesign: the ISE-optimal Kg of the P gap controller Vz = Kg*(Tdr - Td) "
      "(seed 004 eq. 1-3, docs/blocks.md)",
      "edm-kgdesign");
  app.add_option_function<std::string>(
      "--law",
      [&](const std::string& v) {
        if (v != "drill" && v != "sink") {
          edm::apps::reject("--law must be drill or sink, got '" + v + "'");
        }
        law = v == "drill" ? TdMedianLaw::drill() : TdMedianLaw::sink();
        law_name = v;
      },
      "Td median law of PLANT-MODEL 6.5 (default drill)");
  const auto number = [&](const char* flag, std::optional<double>& slot, const char* help) {
    app.add_option(flag, slot, help)->check(edm::apps::kFinite);
  };
  number("--gap-um", gap_um, "working gap [um] (default: the law's g_r, 20 for drill)");
  number("--debris", debris, "debris concentration c in [0, 1] at the working point (default 0)");
  number("--kd-us-per-um", kd, "Td slope, overrides the law");
  number("--tau-v-ms", tau_v_ms, "first-order velocity loop, time constant [ms]");
  number("--wn", wn, "second-order axis, command -> velocity (default 200 rad/s)");
  number("--zeta", zeta, "its damping (default 0.55)");
  number("--tau-m-ms", tau_m_ms, "first-order lag on the measured Td [ms] (default 0: none)");
  number("--tdr-us", tdr_us, "size of the Tdr step used for J [us] (default 1; J scales with D^2)");
  number("--kg", kg_eval, "also evaluate this Kg [(mm/s)/us]");
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) return *code;
  if (tau_v_ms && (wn || zeta)) return bad("--tau-v-ms excludes --wn/--zeta (pick one axis model)");

  if (debris) law.debris = *debris;
  if (const auto errs = law.validate(); !errs.empty()) return bad("Td law: " + errs.front());
  const double gap = gap_um.value_or(law.params.td_gap_ref_um);
  if (gap_um && !(gap > 0.0)) return bad("--gap-um must be > 0");

  GapLoopModel m;
  m.kd_us_per_um = kd.value_or(edm::kgdesign::td_gap_slope_us_per_um(law, gap));
  if (tau_v_ms) {
    m.axis.order = AxisOrder::kFirstOrder;
    m.axis.tau_v_s = *tau_v_ms * 1e-3;
  } else {
    m.axis.order = AxisOrder::kSecondOrder;
    m.axis.wn_rad_s = wn.value_or(m.axis.wn_rad_s);
    m.axis.zeta = zeta.value_or(m.axis.zeta);
  }
  m.tau_meas_s = tau_m_ms.value_or(0.0) * 1e-3;
  m.tdr_step_us = tdr_us.value_or(1.0);
  if (const auto errs = m.validate(); !errs.empty()) return bad("model: " + errs.front());
  if (kg_eval && !(*kg_eval > 0.0)) return bad("--kg must be > 0");

  const auto r = edm::kgdesign::optimal_kg(m);
  if (r.status == KgDesignStatus::kInvalidModel) return bad("model: " + r.errors.front());

  std::printf("edm-kgdesign: ISE-optimal Kg of the P gap controller Vz = Kg*(Tdr - Td)\n");
  std::printf("model\n");
  if (kd) {
    std::printf("  kd              %.6g us/um (given)\n", m.kd_us_per_um);
  } else {
    std::printf("  Td law (%s)   tau_med = %g + %g*exp((g - %g)/%g)*exp(-%g*%g) us\n",
                law_name.c_str(), law.params.td_tau_min_us, law.params.td_tau_ref_us,
                law.params.td_gap_ref_um, law.params.td_len_um, law.params.td_debris_k, law.debris);
    std::printf("  working gap     %g um, Td median %.4g us (the Tdr that holds it)\n", gap,
                edm::kgdesign::td_median_us(law, gap));
    std::printf("  kd              %.6g us/um (slope of the law at the gap)\n", m.kd_us_per_um);
  }
  if (m.axis.order == AxisOrder::kFirstOrder) {
    std::printf("  axis            1st order, tau_v %g ms (command -> velocity)\n",
                m.axis.tau_v_s * 1e3);
  } else {
    std::printf("  axis            2nd order, wn %g rad/s, zeta %g (command -> velocity)\n",
                m.axis.wn_rad_s, m.axis.zeta);
  }
  if (m.tau_meas_s > 0.0) {
    std::printf("  Td measurement  1st-order lag %g ms\n", m.tau_meas_s * 1e3);
  } else {
    std::printf("  Td measurement  no lag\n");
  }
  std::printf("  loop            L(s) = K*G_axis(s)*H_m(s)/s, K = 1000*Kg*kd [1/s]\n");
  std::printf("  Tdr step        %g us\n", m.tdr_step_us);
  std::printf("  E(s) = B/A      order n = %d, ascending powers of s, at the optimum:\n", r.order);
  std::printf("    B = %s\n", format_poly(r.transfer.b).c_str());
  std::printf("    A = %s\n", format_poly(r.transfer.a).c_str());
  std::printf("design\n");
  if (std::isfinite(r.critical_kg)) {
    std::printf("  Kg critical     %.6g (mm/s)/us (stability limit, K = %.6g 1/s)\n", r.critical_kg,
                edm::kgdesign::loop_gain_per_s(m, r.critical_kg));
  } else {
    std::printf("  Kg critical     none (stable for every Kg > 0)\n");
  }
  if (r.status == KgDesignStatus::kNoFiniteMinimum) {
    std::printf("  Kg optimal      none: J falls monotonically as Kg grows\n");
    std::printf("  J infimum       %.6g us^2*s (approached as Kg -> inf)\n", r.ise_us2_s);
    std::printf(
        "  note            ISE does not penalise the oscillation that a large Kg brings;\n"
        "                  model the Td measurement lag (--tau-m-ms) or the 2nd-order axis\n");
  } else {
    std::printf("  Kg optimal      %.6g (mm/s)/us (K = %.6g 1/s, gain margin %.3g)\n",
                r.kg_mm_s_per_us, r.loop_gain_per_s, r.critical_kg / r.kg_mm_s_per_us);
    std::printf("  J               %.6g us^2*s\n", r.ise_us2_s);
    print_poles(r.poles);
  }
  if (kg_eval) {
    const double j = edm::kgdesign::ise_for_kg(m, *kg_eval);
    std::printf("at --kg %g (mm/s)/us\n", *kg_eval);
    if (std::isfinite(j)) {
      std::printf("  J               %.6g us^2*s (%.3g x the optimum)\n", j,
                  r.status == KgDesignStatus::kOk ? j / r.ise_us2_s : std::nan(""));
    } else {
      std::printf("  J               inf (closed loop unstable)\n");
    }
    const auto t = edm::kgdesign::error_transfer(m, *kg_eval);
    print_poles(edm::kgdesign::polynomial_roots(t.a));
  }
  return edm::apps::kExitOk;
}
