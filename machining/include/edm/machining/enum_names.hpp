#pragma once
// An enum's names as a table indexed by the enumerator's value: the one to_string / from_string
// pair behind MotionKind and the bridge's ErrorCode. The table's size is the enum's count
// constant, so the table and the enum are declared side by side.
// RT-safe (no allocation, noexcept); thread-safe (pure functions over constant tables).

#include <array>
#include <cstddef>
#include <string_view>

namespace edm::machining {

/// names[e], or "?" for a value outside the table.
template <class E, std::size_t N>
constexpr std::string_view enum_name(const std::array<std::string_view, N>& names, E e) noexcept {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? names[i] : std::string_view{"?"};
}

/// Sets `out` to the enumerator named `s`; false (out unchanged) if no name matches.
template <class E, std::size_t N>
constexpr bool enum_from_name(const std::array<std::string_view, N>& names, std::string_view s,
                              E& out) noexcept {
  for (std::size_t i = 0; i < N; ++i) {
    if (names[i] == s) {
      out = static_cast<E>(i);
      return true;
    }
  }
  return false;
}

}  // namespace edm::machining
