#pragma once
// OrbitExpander: grows the orbit radius once per revolution from the mean ignition delay of that
// revolution (SEEDS 004, eq. 20–21), for finishing a hole wall by orbiting.
//
//   on a rising edge of start (and not busy): radius = r0_mm, final = final_radius_mm (latched),
//       revolutions = 0; busy unless r0 = final (then done at once)
//   each cycle while busy and enable: if valid, Σ += td_us and n += 1 (invalid samples are not
//       read); then, if the revolution ended this cycle:
//       Tdm = Σ/n                              (eq. 20; Tdm = 0 when n = 0)
//       Δr  = clamp(kr·Tdm, 0, dr_max_mm)      (eq. 21; Δr = 0 when n = 0: no data, no growth)
//       Δr  = min(Δr, final − radius);  radius += Δr;  revolutions += 1;  Σ = n = 0
//       radius = final → busy = false, done = true (radius is set to final exactly)
//
// A revolution ends on a rising edge of rev_pulse (samples_per_rev = 0) or after samples_per_rev
// enabled samples (samples_per_rev > 0; rev_pulse is then ignored). The sample of the cycle in
// which the revolution ends belongs to that revolution. enable = false pauses: no sample is
// collected, no revolution ends, the partial sums are kept. The new radius is the radius for the
// next revolution. `done` is a level, true until the next start. A start edge while busy is
// ignored; the start cycle itself is not a sample (collection begins in the next cycle).
//
// Status: kSaturated in the cycle in which Δr was cut to dr_max_mm; kFault on a non-finite td_us
// with valid = true (the sample is excluded), on a rejected start (r0 or final non-finite,
// r0 < 0 or final < r0; nothing latched), or on a revolution whose sum overflowed (Δr = 0).
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/rising_edge.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct OrbitExpanderParams {
  static constexpr std::int64_t kMaxSamplesPerRev = 1'000'000'000;

  double kr{1e-4};                  // [mm/µs] Δr per µs of mean ignition delay, ≥ 0
  double dr_max_mm{0.01};           // [mm] largest Δr per revolution, ≥ 0
  std::int64_t samples_per_rev{0};  // samples per revolution; 0 = revolutions from rev_pulse

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): kr up to 1 mm/µs (x a mean Td of 10-100 µs: 10-100 mm a revolution, far
    // past the seed 004 default 1e-4 that "too large a kr shorts the gap"; dr_max, at most 10 mm,
    // clamps the step).
    v.param("kr", kr,
            {"mm/us", "radius growth per revolution per us of mean ignition delay",
             rt::closed(0.0, 1.0)});
    v.param("dr_max_mm", dr_max_mm,
            {"mm", "largest radius growth per revolution", ranges::kToleranceMm});
    v.param("samples_per_rev", samples_per_rev,
            {"", "samples per revolution (0: a rising edge of rev_pulse ends a revolution)",
             rt::closed(0.0, static_cast<double>(kMaxSamplesPerRev))});
  }
};

class OrbitExpander final : public rt::BlockWithParams<OrbitExpanderParams> {
 public:
  static constexpr std::int64_t kMaxSamplesPerRev = OrbitExpanderParams::kMaxSamplesPerRev;
  /// Non-RT. Idle, radius 0.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (Δr clamped to dr_max_mm) or kFault (see the file comment).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  void publish() noexcept;
  /// Zero increment, mean Td, sums and revolution count: the state of a move not yet begun.
  void clear_progress() noexcept;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<bool> start{pins_, "start"};
  rt::Input<double> r0_mm{pins_, "r0_mm", "mm"};
  rt::Input<double> final_radius_mm{pins_, "final_radius_mm", "mm"};
  rt::Input<bool> enable{pins_, "enable", "", true};
  rt::Input<double> td_us{pins_, "td_us", "us"};
  rt::Input<bool> valid{pins_, "valid"};
  rt::Input<bool> rev_pulse{pins_, "rev_pulse"};
  rt::Output<double> radius_mm{pins_, "radius_mm", "mm"};
  rt::Output<double> dr_mm{pins_, "dr_mm", "mm"};
  rt::Output<double> tdm_us{pins_, "tdm_us", "us"};
  rt::Output<std::int64_t> revolutions{pins_, "revolutions"};
  rt::Output<bool> busy{pins_, "busy"};
  rt::Output<bool> done{pins_, "done"};

 private:
  double radius_mm_{0.0};
  double final_mm_{0.0};
  double dr_mm_{0.0};
  double tdm_us_{0.0};
  double sum_us_{0.0};  // Σ td over the valid samples of the current revolution [µs]
  std::int64_t n_valid_{0};
  std::int64_t n_samples_{0};  // enabled samples of the current revolution
  std::int64_t revs_{0};
  bool busy_state_{false};
  bool done_state_{false};
  RisingEdge start_edge_;
  RisingEdge rev_edge_;
};

}  // namespace edm::blocks
