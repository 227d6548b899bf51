#include "edm/runtime/time.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>

namespace edm::rt {

namespace {

struct Unit {
  std::string_view suffix;
  double ns;
};
// Longest suffixes first so "ms" is not read as "m" + "s".
constexpr Unit kUnits[] = {{"min", 60e9}, {"ns", 1.0}, {"us", 1e3}, {"ms", 1e6}, {"s", 1e9}};

}  // namespace

DurationParse parse_duration(std::string_view text) {
  std::string_view t = text;
  while (!t.empty() && t.front() == ' ') {
    t.remove_prefix(1);
  }
  while (!t.empty() && t.back() == ' ') {
    t.remove_suffix(1);
  }
  if (t.empty()) {
    return {std::nullopt, "empty duration"};
  }
  for (const Unit& u : kUnits) {
    if (t.size() <= u.suffix.size() || t.substr(t.size() - u.suffix.size()) != u.suffix) {
      continue;
    }
    std::string_view num = t.substr(0, t.size() - u.suffix.size());
    while (!num.empty() && num.back() == ' ') {
      num.remove_suffix(1);
    }
    double v = 0.0;
    auto [end, ec] = std::from_chars(num.data(), num.data() + num.size(), v);
    if (ec != std::errc{} || end != num.data() + num.size() || num.empty()) {
      return {std::nullopt, "'" + std::string(text) + "' is not a duration (e.g. 250us, 1ms, 2s)"};
    }
    if (!std::isfinite(v) || v < 0.0) {
      return {std::nullopt, "duration '" + std::string(text) + "' must be finite and >= 0"};
    }
    const double ns = v * u.ns;
    if (ns > 9.2e18) {
      return {std::nullopt, "duration '" + std::string(text) + "' is too large"};
    }
    if (std::abs(ns - std::round(ns)) > 1e-6 * std::max(1.0, ns)) {
      return {std::nullopt, "duration '" + std::string(text) + "' is finer than 1ns"};
    }
    return {Duration{static_cast<std::int64_t>(std::llround(ns))}, {}};
  }
  double dummy = 0.0;
  auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), dummy);
  if (ec == std::errc{} && end == t.data() + t.size()) {
    return {std::nullopt,
            "duration '" + std::string(text) + "' needs a unit (ns, us, ms, s, min), e.g. 1ms"};
  }
  return {std::nullopt, "'" + std::string(text) + "' is not a duration (e.g. 250us, 1ms, 2s)"};
}

std::string format_duration(Duration d) {
  const std::int64_t ns = d.count();
  if (ns != 0 && ns % 1'000'000'000 == 0) {
    return std::to_string(ns / 1'000'000'000) + "s";
  }
  if (ns != 0 && ns % 1'000'000 == 0) {
    return std::to_string(ns / 1'000'000) + "ms";
  }
  if (ns != 0 && ns % 1'000 == 0) {
    return std::to_string(ns / 1'000) + "us";
  }
  return std::to_string(ns) + "ns";
}

}  // namespace edm::rt
