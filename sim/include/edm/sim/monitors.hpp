#pragma once
// Small stateful pieces of the plant: the WEDM thickness profile H(s), the wire-break monitor
// (§6.4) and the Rab window (§6.2 step 8). Fixed capacity, so the plant's loop never allocates.
//
// RT-safety: everything but ThicknessProfile::make() is noexcept and allocation-free.
// Thread-safety: one thread per object.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "edm/sim/params.hpp"

namespace edm::sim {

/// H(s): part thickness as a step function of the cut length.
class ThicknessProfile {
 public:
  ThicknessProfile() = default;
  /// Parses the profile text (params.hpp); nullopt and *error on a bad one. Non-RT.
  static std::optional<ThicknessProfile> make(std::string_view text, std::string* error);
  [[nodiscard]] double thickness_mm(double cut_mm) const noexcept;

 private:
  std::array<ThicknessStep, kMaxThicknessSteps> steps_{};
  std::size_t size_{0};
};

/// I_BK = I_BK,ref (H / 10 mm)^0.5 f (§6.4, Sato: sub-linear in H, lower with poor flushing).
double wire_break_current_a(double ibk_ref_a, double thickness_mm, double flush_f) noexcept;

/// The damage the wire tolerates in this run: Gamma(shape, 1/shape) (mean 1, CV 1/√shape), the
/// mean of `shape` Exp(1) variates drawn from the seed's wire-break stream at indices
/// 0 … shape − 1; shape 1 is the Exp(1) variate at index 0. shape is clamped to
/// 1 … kMaxWireBreakShape. Pure.
double wire_break_threshold(std::uint64_t seed, int shape) noexcept;

/// Latches "broken" on either of two rupture mechanisms (docs/simulator.md §7):
///  - mean energy (Sato): Ī > I_BK has held for current_ns;
///  - abnormal discharges (seed 000, Liao: Rab is the precursor of rupture): a hazard
///    λ = exp((R̄ − rab_ref) / rab_width) / rab_mean_ns on R̄, Rab through a first-order lag
///    rab_tau_ns (the wire's heat memory: one noisy window does not break it), so the mean time
///    to break at
///    Rab = rab_ref is rab_mean_ns and it falls e-fold every rab_width above. The wire breaks when
///    ∫λ dt reaches `threshold`, the tolerated damage the plant draws from its seed
///    (wire_break_threshold) — exact whatever the update steps, and the same for every
///    controller (common random numbers).
class WireBreakMonitor {
 public:
  WireBreakMonitor() = default;
  WireBreakMonitor(std::int64_t current_ns, double rab_ref, std::int64_t rab_mean_ns,
                   double rab_width, std::int64_t rab_tau_ns, double threshold) noexcept
      : current_ns_(current_ns),
        rab_ref_(rab_ref),
        rab_mean_ns_(rab_mean_ns),
        rab_width_(rab_width),
        rab_tau_ns_(rab_tau_ns),
        threshold_(threshold) {}
  /// The conditions held (or not) over the last dt_ns. Returns broken().
  bool update(std::int64_t dt_ns, double mean_current_a, double break_current_a,
              double rab) noexcept;
  [[nodiscard]] bool broken() const noexcept { return broken_; }
  /// ∫λ dt so far (the wire breaks at threshold()).
  [[nodiscard]] double hazard() const noexcept { return hazard_; }
  [[nodiscard]] double threshold() const noexcept { return threshold_; }
  /// R̄, the lagged Rab the hazard acts on.
  [[nodiscard]] double rab_lagged() const noexcept { return rab_lag_; }
  /// λ at this Rab, per second.
  [[nodiscard]] double rate_per_s(double rab) const noexcept;
  void reset() noexcept { over_current_ns_ = 0, hazard_ = rab_lag_ = 0.0, broken_ = false; }

 private:
  std::int64_t current_ns_{5'000'000};
  double rab_ref_{0.5};
  std::int64_t rab_mean_ns_{100'000'000};
  double rab_width_{0.02};
  std::int64_t rab_tau_ns_{200'000'000};
  double threshold_{1.0};
  double rab_lag_{0.0};
  std::int64_t over_current_ns_{0};
  double hazard_{0.0};
  bool broken_{false};
};

/// (arc + short) / total pulses over a sliding window of kBins time bins.
class RabWindow {
 public:
  static constexpr std::size_t kBins = 32;
  static_assert((kBins & (kBins - 1)) == 0, "kBins must be a power of two");
  RabWindow() = default;
  explicit RabWindow(std::int64_t window_ns) noexcept
      : bin_ns_(window_ns / static_cast<std::int64_t>(kBins) > 0
                    ? window_ns / static_cast<std::int64_t>(kBins)
                    : 1) {}
  void add(std::int64_t t_ns, bool abnormal) noexcept;
  /// Rab over the window ending at t_ns; 0 when it holds no pulse.
  [[nodiscard]] double rab(std::int64_t t_ns) noexcept;

 private:
  void roll(std::int64_t t_ns) noexcept;
  std::int64_t bin_ns_{1'250'000};
  std::int64_t head_{0};  // index of the newest bin (time / bin_ns)
  std::array<std::uint32_t, kBins> total_{}, abnormal_{};
};

}  // namespace edm::sim
