#include "edm/runtime/log_limiter.hpp"

#include <algorithm>
#include <vector>

namespace edm::rt {

bool LogRateLimiter::admit(std::string_view key, Clock::time_point now, std::uint64_t& suppressed) {
  suppressed = 0;
  std::lock_guard lock(mutex_);
  auto it = buckets_.find(std::string(key));
  if (it == buckets_.end()) {
    if (buckets_.size() >= opt_.max_keys) forget_one();
    it = buckets_.emplace(std::string(key), Bucket{opt_.burst, now, {}, 0}).first;
  }
  Bucket& b = it->second;
  const double dt = std::chrono::duration<double>(now - b.refilled).count();
  if (dt > 0.0) {
    b.tokens = std::min(opt_.burst, b.tokens + dt * opt_.per_s);
    b.refilled = now;
  }
  if (b.tokens < 1.0) {
    ++b.suppressed;
    ++total_;
    b.last_suppressed = now;
    return false;
  }
  b.tokens -= 1.0;
  suppressed = b.suppressed;
  b.suppressed = 0;
  return true;
}

void LogRateLimiter::sweep(Clock::time_point now, std::chrono::milliseconds quiet,
                           const std::function<void(const std::string&, std::uint64_t)>& fn) {
  std::vector<std::pair<std::string, std::uint64_t>> due;
  {
    std::lock_guard lock(mutex_);
    for (auto it = buckets_.begin(); it != buckets_.end();) {
      Bucket& b = it->second;
      if (b.suppressed > 0 && now - b.last_suppressed >= quiet) {
        due.emplace_back(it->first, b.suppressed);
        b.suppressed = 0;
      }
      // A full bucket with nothing to report is the same as no record: forget it.
      const double dt = std::chrono::duration<double>(now - b.refilled).count();
      if (b.suppressed == 0 && b.tokens + dt * opt_.per_s >= opt_.burst) {
        it = buckets_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const auto& [key, n] : due) fn(key, n);  // outside the lock: fn logs
}

std::uint64_t LogRateLimiter::suppressed_total() const {
  std::lock_guard lock(mutex_);
  return total_;
}

void LogRateLimiter::forget_one() {
  // The key that refilled longest ago; its unreported count is lost (still in total_).
  auto oldest = buckets_.begin();
  for (auto it = buckets_.begin(); it != buckets_.end(); ++it) {
    if (it->second.refilled < oldest->second.refilled) oldest = it;
  }
  if (oldest != buckets_.end()) buckets_.erase(oldest);
}

std::string suppressed_note(std::uint64_t n) {
  if (n == 0) return {};
  return " (" + std::to_string(n) + (n == 1 ? " earlier line" : " earlier lines") +
         " from this peer suppressed)";
}

}  // namespace edm::rt
