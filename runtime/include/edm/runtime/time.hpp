#pragma once
// Time types of the runtime and parsing of YAML durations ("250us", "1ms", "2.5s").
// Thread-safe: all functions are pure. RT-safe: the types; parse_duration is non-RT (may allocate).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace edm::rt {

/// All runtime durations are integral nanoseconds.
using Duration = std::chrono::nanoseconds;

/// A point on the runtime's monotonic time line, as nanoseconds since the clock's origin
/// (CLOCK_MONOTONIC's epoch for the real clock, 0 for the virtual clock).
using TimePoint = std::chrono::nanoseconds;

/// Result of parsing a duration: the value, or a message saying what is wrong.
struct DurationParse {
  std::optional<Duration> value;
  std::string error;
};

/// Parses a duration written as a number with a unit: ns, us, ms, s, min (e.g. "250us", "1.5ms").
/// A bare number is an error (units are mandatory). Negative values are errors.
DurationParse parse_duration(std::string_view text);

/// Formats a duration with the largest unit that keeps it exact (e.g. 1500000ns → "1500us").
std::string format_duration(Duration d);

constexpr double to_seconds(Duration d) noexcept { return static_cast<double>(d.count()) / 1e9; }
constexpr double to_micros(Duration d) noexcept { return static_cast<double>(d.count()) / 1e3; }

}  // namespace edm::rt
