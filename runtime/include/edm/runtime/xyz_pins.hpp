#pragma once
// Xyz<P>: one pin per axis, X, Y and Z, declared together in a block's pin table — the axis
// triples of a motion block (positions, velocity commands, reference switches, claims) — and
// indexed by axis (kAxisX, kAxisY, kAxisZ) so that per-axis logic is one loop:
//
//   rt::Xyz<rt::Output<double>> v_cmd{pins_, {"vx_cmd_mm_s", "vy_cmd_mm_s", "vz_cmd_mm_s"},
//   "mm/s"}; for (rt::Output<double>& v : v_cmd) v.set(0.0);
//
// Each pin keeps its own name, wired by a config as any other, and is listed in X, Y, Z order.
// Non-RT: construction; the pins are RT-safe as any pin (pin.hpp).

#include <array>
#include <cstddef>
#include <string_view>

#include "edm/runtime/pin.hpp"

namespace edm::rt {

inline constexpr std::size_t kAxisX = 0, kAxisY = 1, kAxisZ = 2, kAxes = 3;

template <class P>
class Xyz {
 public:
  Xyz(PinTable& owner, const std::array<std::string_view, kAxes>& names, std::string_view unit = {})
      // Each pin is built in place (guaranteed elision): it registers its own address.
      : pins_{{P{owner, names[kAxisX], unit}, P{owner, names[kAxisY], unit},
               P{owner, names[kAxisZ], unit}}} {}

  P& operator[](std::size_t axis) noexcept { return pins_[axis]; }
  const P& operator[](std::size_t axis) const noexcept { return pins_[axis]; }
  P& x() noexcept { return pins_[kAxisX]; }
  P& y() noexcept { return pins_[kAxisY]; }
  P& z() noexcept { return pins_[kAxisZ]; }
  [[nodiscard]] const P& x() const noexcept { return pins_[kAxisX]; }
  [[nodiscard]] const P& y() const noexcept { return pins_[kAxisY]; }
  [[nodiscard]] const P& z() const noexcept { return pins_[kAxisZ]; }
  auto begin() noexcept { return pins_.begin(); }
  auto end() noexcept { return pins_.end(); }
  [[nodiscard]] auto begin() const noexcept { return pins_.begin(); }
  [[nodiscard]] auto end() const noexcept { return pins_.end(); }

 private:
  std::array<P, kAxes> pins_;
};

}  // namespace edm::rt
