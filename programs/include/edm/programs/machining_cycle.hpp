#pragma once
// MachiningCycle: what the job sequencer needs of a machining cycle, whatever it machines (the
// drill's deep hole, the orbit's wall finish; the wire's contour and the sink's cavity next).
// A cycle is a block (usually a composite) and a child of the job; the job starts it from a
// motion block by driving its inputs, steps it every cycle, and asks it through this interface:
//   running()       between its start and its end (DONE or IDLE): it commands axes();
//   axes()          which axes it commands now and at what speed: the job's AxisArbiter gives
//                   them to it (before the position loops, after manual motion);
//   generator_on()  it wants the generator on (the job ANDs it with the condition's arming);
//   abort()         the job was stopped by the operator: end as in the safe state.
// docs/runtime.md "Machining cycles" tells how a new cycle plugs in. RT-safe members.

#include <array>

#include "edm/runtime/xyz_pins.hpp"

namespace edm::programs {

struct AxisClaim {
  std::array<bool, rt::kAxes> claimed{};   // X, Y, Z (rt::kAxisX …)
  std::array<double, rt::kAxes> v_mm_s{};  // the cycle's speed command of a claimed axis

  static AxisClaim xy(double vx_mm_s, double vy_mm_s) noexcept {
    return {{true, true, false}, {vx_mm_s, vy_mm_s, 0.0}};
  }
  static AxisClaim z(double vz_mm_s) noexcept {
    return {{false, false, true}, {0.0, 0.0, vz_mm_s}};
  }
};

class MachiningCycle {
 public:
  [[nodiscard]] virtual bool running() const noexcept = 0;
  [[nodiscard]] virtual AxisClaim axes() const noexcept = 0;
  [[nodiscard]] virtual bool generator_on() const noexcept = 0;
  virtual void abort() noexcept = 0;

 protected:
  MachiningCycle() = default;
  MachiningCycle(const MachiningCycle&) = default;
  MachiningCycle& operator=(const MachiningCycle&) = default;
  ~MachiningCycle() = default;
};

}  // namespace edm::programs
