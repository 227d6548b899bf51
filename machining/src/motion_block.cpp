#include "edm/machining/motion_block.hpp"

#include <array>

namespace edm::machining {
namespace {
constexpr std::array<std::string_view, kMotionKindCount> kNames{
    "rapid", "linear",    "arc_cw",   "arc_ccw",  "drill", "orbit_finish",
    "dwell", "condition", "rotation", "flushing", "end"};
}  // namespace

std::string_view to_string(MotionKind k) noexcept {
  const auto i = static_cast<std::size_t>(k);
  return i < kNames.size() ? kNames[i] : std::string_view{"?"};
}

bool motion_kind_from_string(std::string_view s, MotionKind& out) noexcept {
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (kNames[i] == s) {
      out = static_cast<MotionKind>(i);
      return true;
    }
  }
  return false;
}

}  // namespace edm::machining
