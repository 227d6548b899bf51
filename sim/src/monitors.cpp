#include "edm/sim/monitors.hpp"

#include <algorithm>
#include <cmath>

#include "edm/sim/random.hpp"

namespace edm::sim {

std::optional<ThicknessProfile> ThicknessProfile::make(std::string_view text, std::string* error) {
  const auto steps = parse_thickness_profile(text, error);
  if (!steps) return std::nullopt;
  ThicknessProfile p;
  for (const auto& s : *steps) p.steps_[p.size_++] = s;
  return p;
}

double ThicknessProfile::thickness_mm(double cut_mm) const noexcept {
  double h = size_ > 0 ? steps_[0].thickness_mm : 0.0;
  for (std::size_t i = 1; i < size_ && cut_mm >= steps_[i].from_mm; ++i) h = steps_[i].thickness_mm;
  return h;
}

double wire_break_current_a(double ibk_ref_a, double thickness_mm, double flush_f) noexcept {
  return ibk_ref_a * std::sqrt(thickness_mm / 10.0) * flush_f;
}

double WireBreakMonitor::rate_per_s(double rab) const noexcept {
  const double x = std::min((rab - rab_ref_) / rab_width_, 50.0);  // e^50: breaks at once anyway
  return std::exp(x) / (static_cast<double>(rab_mean_ns_) * 1e-9);
}

double wire_break_threshold(std::uint64_t seed, int shape) noexcept {
  const int k = std::clamp(shape, 1, kMaxWireBreakShape);
  double sum = 0.0;
  for (int i = 0; i < k; ++i) {
    sum -= std::log1p(-uniform(seed, Stream::kWireBreak, static_cast<std::uint64_t>(i)));
  }
  return sum / static_cast<double>(k);
}

bool WireBreakMonitor::update(std::int64_t dt_ns, double mean_current_a, double break_current_a,
                              double rab) noexcept {
  over_current_ns_ = mean_current_a > break_current_a ? over_current_ns_ + dt_ns : 0;
  rab_lag_ += (rab - rab_lag_) *
              (1.0 - std::exp(-static_cast<double>(dt_ns) / static_cast<double>(rab_tau_ns_)));
  hazard_ += rate_per_s(rab_lag_) * static_cast<double>(dt_ns) * 1e-9;
  if (over_current_ns_ >= current_ns_ || hazard_ >= threshold_) broken_ = true;
  return broken_;
}

void RabWindow::roll(std::int64_t t_ns) noexcept {
  const std::int64_t bin = t_ns / bin_ns_;
  if (bin <= head_) return;
  const std::int64_t n = std::min<std::int64_t>(bin - head_, static_cast<std::int64_t>(kBins));
  for (std::int64_t i = 1; i <= n; ++i) {
    const auto k = static_cast<std::size_t>(head_ + i) & (kBins - 1);
    total_[k] = abnormal_[k] = 0;
  }
  head_ = bin;
}

void RabWindow::add(std::int64_t t_ns, bool abnormal) noexcept {
  roll(t_ns);
  const auto k = static_cast<std::size_t>(head_) & (kBins - 1);
  ++total_[k];
  if (abnormal) ++abnormal_[k];
}

double RabWindow::rab(std::int64_t t_ns) noexcept {
  roll(t_ns);
  std::uint64_t tot = 0, abn = 0;
  for (std::size_t i = 0; i < kBins; ++i) tot += total_[i], abn += abnormal_[i];
  return tot == 0 ? 0.0 : static_cast<double>(abn) / static_cast<double>(tot);
}

}  // namespace edm::sim
