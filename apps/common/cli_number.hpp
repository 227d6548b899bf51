#pragma once
// Command-line numbers for the offline tools (edm-kgdesign, edm-wiremap): the whole argument
// must be a finite number, or there is none. Non-RT.

#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

namespace edm::apps {

inline std::optional<double> parse_number(std::string_view text) {
  const std::string s(text);
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace edm::apps
