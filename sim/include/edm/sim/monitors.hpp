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

/// Latches "broken" once Ī > I_BK has held for current_ns, or Rab > rab_limit for rab_ns.
class WireBreakMonitor {
 public:
  WireBreakMonitor() = default;
  WireBreakMonitor(std::int64_t current_ns, double rab_limit, std::int64_t rab_ns) noexcept
      : current_ns_(current_ns), rab_limit_(rab_limit), rab_ns_(rab_ns) {}
  /// The conditions held (or not) over the last dt_ns. Returns broken().
  bool update(std::int64_t dt_ns, double mean_current_a, double break_current_a,
              double rab) noexcept;
  [[nodiscard]] bool broken() const noexcept { return broken_; }
  void reset() noexcept { over_current_ns_ = over_rab_ns_ = 0, broken_ = false; }

 private:
  std::int64_t current_ns_{5'000'000};
  double rab_limit_{0.5};
  std::int64_t rab_ns_{100'000'000};
  std::int64_t over_current_ns_{0}, over_rab_ns_{0};
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
