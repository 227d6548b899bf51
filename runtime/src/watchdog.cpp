#include "edm/runtime/watchdog.hpp"

#include <algorithm>
#include <limits>

namespace edm::rt {
namespace {

// A huge time * sensitivity must not wrap into a small (always tripping) limit.
Duration saturating_multiply(Duration time, int factor) noexcept {
  constexpr auto kMax = std::numeric_limits<Duration::rep>::max();
  if (time.count() > 0 && time.count() > kMax / factor) {
    return Duration{kMax};
  }
  return time * factor;
}

}  // namespace

Watchdog::Watchdog(const WatchdogSpec& spec) noexcept
    : enabled_(spec.enabled),
      action_(spec.action),
      sensitivity_(std::max(spec.sensitivity, 1)),
      time_(spec.time),
      single_cycle_limit_(saturating_multiply(spec.time, sensitivity_)) {}

WatchdogVerdict Watchdog::check(Duration exec) noexcept {
  if (!enabled_) {
    return WatchdogVerdict::kOk;
  }
  if (exec <= time_) {
    consecutive_ = 0;
    return WatchdogVerdict::kOk;
  }
  ++consecutive_;
  if (consecutive_ >= sensitivity_ || exec > single_cycle_limit_) {
    consecutive_ = 0;
    return WatchdogVerdict::kTrip;
  }
  return WatchdogVerdict::kOk;
}

}  // namespace edm::rt
