#include "edm/sim/wire_plane.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace edm::sim {
namespace {

constexpr double kMarginMm = 0.5;  // grid beyond the plate: void
constexpr double kFarMm = 2.0;  // |φ| is clamped here (only the boundary's neighbourhood counts)
constexpr double kReuseMm = 0.00025;    // the cached boundary point serves within this distance
constexpr double kErodeDepthMm = 0.05;  // one erosion reaches at most this far past the clearance

}  // namespace

WirePlane::WirePlane(const WirePlaneGeometry& g) : g_(g) {
  h_ = g.cell_mm;
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kDirections;
    cos_[static_cast<std::size_t>(k)] = std::cos(a);
    sin_[static_cast<std::size_t>(k)] = std::sin(a);
  }
  x0_ = g.x_min_mm - kMarginMm;
  y0_ = g.y_min_mm - kMarginMm;
  nx_ = static_cast<long>(std::ceil((g.x_max_mm - g.x_min_mm + 2 * kMarginMm) / h_)) + 1;
  ny_ = static_cast<long>(std::ceil((g.y_max_mm - g.y_min_mm + 2 * kMarginMm) / h_)) + 1;
  phi_.resize(static_cast<std::size_t>(nx_ * ny_));
  for (long j = 0; j < ny_; ++j) {
    const double y = y0_ + static_cast<double>(j) * h_;
    for (long i = 0; i < nx_; ++i) {
      const double x = x0_ + static_cast<double>(i) * h_;
      double d = std::min({x - g.x_min_mm, g.x_max_mm - x, y - g.y_min_mm, g.y_max_mm - y});
      if (g.hole_d_mm > 0.0) {
        d = std::min(d, std::hypot(x - g.hole_x_mm, y - g.hole_y_mm) - g.hole_d_mm / 2.0);
      }
      phi_[static_cast<std::size_t>(j * nx_ + i)] =
          static_cast<float>(std::clamp(d, -kFarMm, kFarMm));
    }
  }
  phi0_ = phi_;
  shell_.resize(1U << 16);
}

double WirePlane::cell_phi(long i, long j) const noexcept {
  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return -kFarMm;
  return phi_[static_cast<std::size_t>(j * nx_ + i)];
}

double WirePlane::phi(double x, double y) const noexcept {
  const double fx = (x - x0_) / h_, fy = (y - y0_) / h_;
  const double ix = std::floor(fx), iy = std::floor(fy);
  if (!(ix >= 0.0 && iy >= 0.0 && ix < static_cast<double>(nx_ - 1) &&
        iy < static_cast<double>(ny_ - 1))) {
    return -kFarMm;  // off the grid (or NaN): void
  }
  const auto i = static_cast<long>(ix), j = static_cast<long>(iy);
  const double tx = fx - ix, ty = fy - iy;
  const double a = cell_phi(i, j), b = cell_phi(i + 1, j);
  const double c = cell_phi(i, j + 1), d = cell_phi(i + 1, j + 1);
  return (a * (1.0 - tx) + b * tx) * (1.0 - ty) + (c * (1.0 - tx) + d * tx) * ty;
}

double WirePlane::crossing(double x, double y, double ux, double uy, double lo,
                           double limit) const noexcept {
  double s0 = lo, f0 = phi(x + s0 * ux, y + s0 * uy);
  if (f0 > 0.0) {  // already in material at the lower bound: the bound was not one
    s0 = 0.0;
    f0 = phi(x, y);
    if (f0 > 0.0) return kFarMm;
  }
  for (double s1 = s0 + h_; s1 < limit + h_; s1 += h_) {
    const double f1 = phi(x + s1 * ux, y + s1 * uy);
    if (f1 > 0.0) {  // the crossing is between s0 and s1: secant steps, bracketed
      double a0 = s0, a1 = s1, g0 = f0, g1 = f1;
      for (int it = 0; it < 3; ++it) {
        const double m = a1 - g1 * (a1 - a0) / (g1 - g0);
        const double gm = phi(x + m * ux, y + m * uy);
        if (gm > 0.0) {
          a1 = m;
          g1 = gm;
        } else {
          a0 = m;
          g0 = gm;
        }
      }
      return a1 - g1 * (a1 - a0) / (g1 - g0);
    }
    s0 = s1;
    f0 = f1;
  }
  return kFarMm;
}

bool WirePlane::search(double x, double y, double& qx, double& qy) const noexcept {
  const double lo = std::max(0.0, -phi(x, y) - 3.0 * h_);
  double best = kFarMm, best_a = 0.0;
  // The last search's direction first: its crossing bounds the other rays' march at once.
  if (cached_ && !cached_none_) best_a = std::atan2(qy_ - cy_, qx_ - cx_);
  const double first = crossing(x, y, std::cos(best_a), std::sin(best_a), lo, best);
  if (first < best) best = first;
  for (std::size_t k = 0; k < kDirections; ++k) {
    const double s = crossing(x, y, cos_[k], sin_[k], lo, best);
    if (s < best) {
      best = s;
      best_a = 2.0 * std::numbers::pi * static_cast<double>(k) / kDirections;
    }
  }
  if (!(best < kFarMm)) return false;
  // Between the rays the nearest point is found by halving the angle (a ray 3.75° off the normal
  // reads a circle of 0.5 mm ~0.4 µm too far).
  for (double step = std::numbers::pi / kDirections; step > 1e-4; step *= 0.5) {
    for (double a : {best_a - step, best_a + step}) {
      const double s =
          crossing(x, y, std::cos(a), std::sin(a), std::max(0.0, best - 2.0 * h_), best);
      if (s < best) {
        best = s;
        best_a = a;
      }
    }
  }
  qx = x + best * std::cos(best_a);
  qy = y + best * std::sin(best_a);
  return true;
}

double WirePlane::clearance_mm(double x, double y) const noexcept {
  if (!active()) return kFarMm;
  const double inside = phi(x, y);
  if (inside > 0.0) return -inside;  // the wire in the material
  const double mx = x - cx_, my = y - cy_;
  if (!cached_ || stale_ || mx * mx + my * my > kReuseMm * kReuseMm) {
    cached_none_ = !search(x, y, qx_, qy_);
    cx_ = x;
    cy_ = y;
    cached_ = true;
    stale_ = false;
  }
  const double dx = qx_ - x, dy = qy_ - y;
  return cached_none_ ? kFarMm : std::sqrt(dx * dx + dy * dy);
}

double WirePlane::cut_thickness_mm(double x, double y) const noexcept {
  double h = g_.thickness_mm;
  if (g_.step_mm != 0.0 && x >= g_.step_x_mm) h += g_.step_mm;
  if (g_.void_d_mm > 0.0 && std::hypot(x - g_.void_x_mm, y - g_.void_y_mm) < g_.void_d_mm / 2.0) {
    h -= g_.void_height_mm;
  }
  return std::max(h, 1e-3);
}

double WirePlane::erode(double x, double y, double reach_mm, double volume_mm3) noexcept {
  if (!active() || !(volume_mm3 > 0.0)) return 0.0;
  const double d = std::max(clearance_mm(x, y), 0.0);
  if (d > reach_mm) return volume_mm3;  // nothing to remove within reach
  // The material a disc about (x, y) of radius R takes: the stamp φ ← min(φ, ρ − R) lowers each
  // cell's material share m(φ) = clamp(φ/h + ½, 0, 1), and A(R) = h² Σ [m(φ) − m(min(φ, ρ − R))]
  // is what it lowers in all (the stamp's own measure, so a kerf's side walls count only once
  // the disc reaches them). R is found so that A(R) = V / H: the field loses the eroded volume,
  // whatever the engaged arc's shape (a main cut's front or a skim's wall).
  const double r_max = d + kErodeDepthMm;
  const double box = r_max + h_;
  const long i0 = std::max(0L, static_cast<long>(std::floor((x - box - x0_) / h_)));
  const long i1 = std::min(nx_ - 1, static_cast<long>(std::ceil((x + box - x0_) / h_)));
  const long j0 = std::max(0L, static_cast<long>(std::floor((y - box - y0_) / h_)));
  const long j1 = std::min(ny_ - 1, static_cast<long>(std::ceil((y + box - y0_) / h_)));
  const auto share = [this](double f) { return std::clamp(f / h_ + 0.5, 0.0, 1.0); };
  std::size_t n = 0;
  for (long j = j0; j <= j1 && n < shell_.size(); ++j) {
    const double cy = y0_ + static_cast<double>(j) * h_ - y;
    const float* row = &phi_[static_cast<std::size_t>(j * nx_)];
    for (long i = i0; i <= i1 && n < shell_.size(); ++i) {
      const double f = row[i];
      if (f <= -0.5 * h_) continue;  // void: nothing to take
      const double cx = x0_ + static_cast<double>(i) * h_ - x;
      const double rho = std::sqrt(cx * cx + cy * cy);
      if (rho < box) shell_[n++] = {rho, f};
    }
  }
  const auto area = [&](double r) {
    double a = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double f = shell_[k].m;
      a += share(f) - share(std::min(f, shell_[k].rho - r));
    }
    return a * h_ * h_;
  };
  const double want = volume_mm3 / cut_thickness_mm(x, y);
  double lo = d - h_, hi = r_max, left = 0.0;
  if (const double all = area(hi); all < want) {  // all that is within reach; the rest is left
    left = (want - all) * cut_thickness_mm(x, y);
    lo = hi;
  } else {
    for (int it = 0; it < 24; ++it) {
      const double mid = 0.5 * (lo + hi);
      (area(mid) < want ? lo : hi) = mid;
    }
  }
  const double r_new = 0.5 * (lo + hi);
  const double stamp = r_new + 2.0 * h_;
  for (long j = j0; j <= j1; ++j) {
    const double cy = y0_ + static_cast<double>(j) * h_ - y;
    float* row = &phi_[static_cast<std::size_t>(j * nx_)];
    for (long i = i0; i <= i1; ++i) {
      const double cx = x0_ + static_cast<double>(i) * h_ - x;
      const double rho = std::sqrt(cx * cx + cy * cy);
      if (rho > stamp) continue;
      row[i] = std::min(row[i], static_cast<float>(std::max(rho - r_new, -kFarMm)));
    }
  }
  stale_ = true;
  return left;
}

double WirePlane::edge_along_mm(double x, double y, double ux, double uy,
                                double max_mm) const noexcept {
  const double step = 0.25 * h_;
  double prev = phi(x, y);
  if (!(prev > 0.0)) return -1.0;
  for (double s = step; s <= max_mm; s += step) {
    const double v = phi(x + s * ux, y + s * uy);
    if (v <= 0.0) return s - step * v / (v - prev);  // linear between the two samples
    prev = v;
  }
  return -1.0;
}

double WirePlane::removed_mm3() const noexcept {
  double cells = 0.0;
  for (std::size_t k = 0; k < phi_.size(); ++k) {
    if (phi0_[k] > 0.0F && phi_[k] <= 0.0F) {
      const double x = x0_ + static_cast<double>(static_cast<long>(k) % nx_) * h_;
      const double y = y0_ + static_cast<double>(static_cast<long>(k) / nx_) * h_;
      cells += cut_thickness_mm(x, y);
    }
  }
  return cells * h_ * h_;
}

}  // namespace edm::sim
