#include "edm/sim/params.hpp"

// The wire thickness profile text ("cut_length_mm:thickness_mm" steps), parsed at configure time.

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace edm::sim {
namespace {

bool parse_double(std::string_view s, double& out) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  if (s.empty()) return false;
  const auto* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, out);
  return r.ec == std::errc{} && r.ptr == end && std::isfinite(out);
}

}  // namespace

std::optional<std::vector<ThicknessStep>> parse_thickness_profile(std::string_view text,
                                                                  std::string* error) {
  std::vector<ThicknessStep> steps;
  auto fail = [&](std::size_t n, std::string_view entry, std::string_view why) {
    if (error != nullptr) {
      *error = "entry " + std::to_string(n) + " ('" + std::string(entry) +
               "'): " + std::string(why) +
               "; expected comma-separated 'cut_length_mm:thickness_mm' steps, e.g. "
               "'0:10,20:60,40:10'";
    }
    return std::nullopt;
  };
  std::size_t n = 0;
  while (true) {
    ++n;
    const auto comma = text.find(',');
    const auto entry = text.substr(0, comma);
    const auto colon = entry.find(':');
    if (colon == std::string_view::npos) return fail(n, entry, "no ':'");
    ThicknessStep st;
    if (!parse_double(entry.substr(0, colon), st.from_mm)) {
      return fail(n, entry, "cut length is not a number");
    }
    if (!parse_double(entry.substr(colon + 1), st.thickness_mm)) {
      return fail(n, entry, "thickness is not a number");
    }
    if (st.thickness_mm <= 0.0) return fail(n, entry, "thickness must be > 0");
    if (steps.empty() && st.from_mm != 0.0) return fail(n, entry, "the first step must start at 0");
    if (!steps.empty() && st.from_mm <= steps.back().from_mm) {
      return fail(n, entry, "cut lengths must increase");
    }
    if (steps.size() == kMaxThicknessSteps) return fail(n, entry, "more than 16 steps");
    steps.push_back(st);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return steps;
}

}  // namespace edm::sim
