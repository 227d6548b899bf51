#include "edm/runtime/clock.hpp"

#include <cerrno>
#include <ctime>

namespace edm::rt {

TimePoint RealClock::now() const noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return TimePoint{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

Duration RealClock::thread_cpu_time() const noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return Duration{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

void RealClock::sleep_until(TimePoint t) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t.count() / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t.count() % 1'000'000'000);
  // Absolute deadline: a signal interrupting the sleep just sleeps again to the same instant.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void VirtualClock::advance_to(TimePoint t) noexcept {
  std::int64_t cur = now_ns_.load(std::memory_order_relaxed);
  while (t.count() > cur &&
         !now_ns_.compare_exchange_weak(cur, t.count(), std::memory_order_acq_rel)) {
  }
}

}  // namespace edm::rt
