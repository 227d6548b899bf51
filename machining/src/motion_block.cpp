#include "edm/machining/motion_block.hpp"

#include <array>

#include "edm/machining/enum_names.hpp"

namespace edm::machining {
namespace {
constexpr std::array<std::string_view, kMotionKindCount> kNames{
    "rapid", "linear",    "arc_cw",   "arc_ccw",  "drill", "orbit_finish",
    "dwell", "condition", "rotation", "flushing", "end",   "program_stop"};
}  // namespace

std::string_view to_string(MotionKind k) noexcept { return enum_name(kNames, k); }

bool motion_kind_from_string(std::string_view s, MotionKind& out) noexcept {
  return enum_from_name(kNames, s, out);
}

}  // namespace edm::machining
