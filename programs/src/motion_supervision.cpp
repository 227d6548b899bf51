#include "edm/programs/motion_supervision.hpp"

namespace edm::programs {

void MotionSupervision::check_limits(rt::TimePoint now, double x, double y, double z) noexcept {
  // The program was checked at commit; this catches drift, jogs and wrong offsets.
  bool outside = false;
  for (const machining::AxisLimits& a : tables_->axes) {
    const double v = a.name == 'X' ? x : (a.name == 'Y' ? y : z);
    if (v < a.min_mm - 1e-9 || v > a.max_mm + 1e-9) outside = true;
  }
  if (outside && !limit_alarm_raised_) {
    machine_->raise({rt::AlarmCode::kSoftLimit, rt::AlarmSeverity::kFault, now, source_,
                     "soft limit: an axis is outside its configured range", 0.0});
    limit_alarm_raised_ = true;
  } else if (!outside) {
    limit_alarm_raised_ = false;
  }
}

void MotionSupervision::check_following_error(rt::TimePoint now, bool fault) noexcept {
  if (fault) {
    machine_->raise({rt::AlarmCode::kFollowingError, rt::AlarmSeverity::kFault, now, source_,
                     "following error: an axis lags its reference beyond f_err_max_mm", 0.0});
  }
}

}  // namespace edm::programs
