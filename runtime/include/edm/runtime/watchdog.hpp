#pragma once
// The task watchdog with CODESYS semantics: it trips when `sensitivity` consecutive cycles each
// run longer than `time`, or when a single cycle runs longer than `time * sensitivity`.
// What a trip does (fault or warn, WatchdogSpec::action) is the task runner's business.
//
// Thread safety: not thread-safe; one instance belongs to one task's RT thread.
// RT safety: check(), consecutive() and reset() are RT-safe (noexcept, O(1), no allocation).

#include <cstdint>

#include "edm/runtime/config.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

enum class WatchdogVerdict : std::uint8_t { kOk, kTrip };

class Watchdog {
 public:
  /// Copies what it needs from `spec` (not the reference). A sensitivity below 1 counts as 1.
  /// @note Non-RT (runs while configuring), noexcept.
  explicit Watchdog(const WatchdogSpec& spec) noexcept;

  /// Feeds one cycle's execution time. "Exceeds" means strictly greater: exec == time is in time.
  /// A cycle in time resets the consecutive count. After a trip the count restarts from 0, so an
  /// overload that continues trips again every `sensitivity` cycles (or at once for cycles over
  /// time * sensitivity). Always kOk when the spec is disabled.
  /// @note RT-safe.
  [[nodiscard]] WatchdogVerdict check(Duration exec) noexcept;

  /// Cycles in a row that exceeded `time` since the last in-time cycle or trip. @note RT-safe.
  [[nodiscard]] int consecutive() const noexcept { return consecutive_; }

  /// Forgets the consecutive count (e.g. when the task restarts after a fault). @note RT-safe.
  void reset() noexcept { consecutive_ = 0; }

  [[nodiscard]] bool enabled() const noexcept { return enabled_; }
  [[nodiscard]] WatchdogAction action() const noexcept { return action_; }

 private:
  bool enabled_;
  WatchdogAction action_;
  int sensitivity_;
  Duration time_;
  Duration single_cycle_limit_;  // time * sensitivity, saturated
  int consecutive_{0};
};

}  // namespace edm::rt
