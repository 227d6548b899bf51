#include "edm/sim/plant.hpp"

// Short events at the servo's gap (docs/simulator.md §4a): the injected contact, debris bridges
// and lateral contacts of a vibrating tube. They force a pulse to be a short before the gap
// physics (gap_model.cpp) is asked. The pulse engine is plant.cpp.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "edm/sim/random.hpp"

namespace edm::sim {
namespace {

// A hazard is integrated over the time since the previous pulse began, at most this long: after
// the generator was off, a bridge does not "owe" the idle time (the debris settled or flushed).
constexpr std::int64_t kMaxHazardIntervalNs = 1'000'000;

}  // namespace

double Plant::tip_z_mm() const noexcept { return axes_[2].position_mm() + wear_length_mm_; }

void Plant::inject_short(edm::rt::Duration duration) noexcept {
  injected_short_end_ns_ = state_.now.count() + duration.count();
}

void Plant::track_short_events() noexcept {
  const auto& p = params_;
  if (contact_ == Contact::kMet && !p.contact_persistent &&
      (tip_z_mm() - contact_tip_mm_) * 1e3 >= p.contact_clear_um) {
    contact_ = Contact::kCleared;
  }
  if (episode_ == ShortCause::kBridge &&
      (tip_z_mm() - episode_tip_mm_) * 1e3 >= p.bridge_clear_um) {
    episode_ = ShortCause::kNone;
  }
}

Plant::ShortCause Plant::short_event(std::int64_t t_ns, std::uint64_t k, double gap_um,
                                     double debris) noexcept {
  const auto& p = params_;
  const double tip = tool_z_mm(t_ns) + wear_length_mm_;
  const double dt_s =
      static_cast<double>(std::min(t_ns - last_pulse_ns_, kMaxHazardIntervalNs)) * 1e-9;
  last_pulse_ns_ = t_ns;
  if (t_ns < injected_short_end_ns_) return ShortCause::kContact;  // a test's short burst

  // The injected contact: met once, when the hole reaches its depth, at the tip's position then.
  if (contact_ == Contact::kArmed && depth_mm() >= p.contact_at_depth_mm) {
    contact_ = Contact::kMet;
    contact_tip_mm_ = tip;
  }
  if (contact_ == Contact::kMet) {
    if ((tip - contact_tip_mm_) * 1e3 < p.contact_clear_um) return ShortCause::kContact;
    if (!p.contact_persistent) contact_ = Contact::kCleared;
  }

  if (!p.short_events || tool_ == Tool::kWire) return ShortCause::kNone;
  if (episode_ != ShortCause::kNone) {
    const bool sheared =
        episode_ == ShortCause::kBridge && (tip - episode_tip_mm_) * 1e3 >= p.bridge_clear_um;
    if (t_ns < episode_end_ns_ && !sheared) return episode_;
    episode_ = ShortCause::kNone;
  }
  // Nothing forms while the electrode is out of the working gap (retracted, or above the work).
  if (!(gap_um < working_gap_um_)) return ShortCause::kNone;

  // The tube's length inside the hole: the side gap a bridge can span, the deflection's lever.
  const double immersed_mm = std::max(0.0, -tip);
  const double bridge_hz = p.bridge_rate_hz *
                           std::pow(debris / p.bridge_debris_ref, p.bridge_debris_exp) *
                           (1.0 + immersed_mm / p.bridge_depth_mm);
  // Tube contact: Rice's rate of up-crossings of ±(side gap) by a Gaussian deflection, and the
  // mean time above the level, so the fraction of time in contact is P(|δ| > side gap).
  double contact_hz = 0.0;
  double contact_life_s = 0.0;
  if (tool_ == Tool::kTube && p.vib_amp_ref_um > 0.0 && immersed_mm > 0.0) {
    const double free_mm = p.tube_guide_mm + immersed_mm;
    const double sigma_um = p.vib_amp_ref_um * std::pow(free_mm / p.vib_len_ref_mm, p.vib_amp_exp);
    const double side_um = (state_.wall_radius_mm - p.tool_od_mm / 2.0) * 1e3;
    const double u = std::max(side_um, 0.0) / sigma_um;
    const double ratio = p.vib_len_ref_mm / free_mm;
    const double f1_hz = p.vib_freq_ref_hz * ratio * ratio;
    const double up_hz = f1_hz * std::exp(-0.5 * u * u);  // one side
    if (up_hz > 0.0) {
      contact_hz = 2.0 * up_hz;
      contact_life_s = 0.5 * std::erfc(u / std::numbers::sqrt2) / up_hz;
    }
  }
  const double total_hz = bridge_hz + contact_hz;
  if (!(total_hz > 0.0)) return ShortCause::kNone;
  if (uniform(seed_, Stream::kShortEvent, k) >= -std::expm1(-total_hz * dt_s)) {
    return ShortCause::kNone;
  }
  const bool bridge = uniform(seed_, Stream::kShortEventKind, k) * total_hz < bridge_hz;
  const double mean_s = bridge ? p.bridge_mean_ms * 1e-3 : contact_life_s;
  const double life_s = -mean_s * std::log(uniform(seed_, Stream::kShortEventLife, k));
  episode_ = bridge ? ShortCause::kBridge : ShortCause::kVibration;
  episode_end_ns_ = t_ns + std::llround(life_s * 1e9);
  episode_tip_mm_ = tip;
  ++(bridge ? state_.bridges : state_.vibration_contacts);
  return episode_;
}

}  // namespace edm::sim
