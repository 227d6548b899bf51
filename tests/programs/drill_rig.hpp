#pragma once
// A DeepHoleDrill driven from test cells (composite_rig.hpp), with its Z position and wear
// compensation switch as cells too.

#include <chrono>
#include <cstdint>

#include "composite_rig.hpp"
#include "edm/programs/deep_hole_drill.hpp"

namespace edm::test {

using namespace std::chrono_literals;

struct Rig : CompositeRig<programs::DeepHoleDrill> {
  programs::DeepHoleDrill& drill{block};
  rt::Output<double> z_mm;
  rt::Output<bool> comp{true};

  explicit Rig(const programs::DeepHoleDrillParams& p) : CompositeRig(p) {
    configure("cycle.drill");
    in<double>("z_mm").connect(z_mm);
    in<bool>("enable_wear_comp").connect(comp);
    activate();
  }
  double vz() { return out<double>("vz_cmd_mm_s"); }
  // Wires `servo` to vz_servo_mm_s and binds again, as the runtime does after the YAML wiring.
  void wire_servo(rt::Output<double>& servo) {
    in<double>("vz_servo_mm_s").connect(servo);
    drill.bind();
  }
  // Sets start, then runs `cycles` cycles with `n` sparks each at a mean Td of `td_us`.
  void start_sparking(std::int64_t n, double td_us, int cycles) {
    start.set(true);
    sparks(n, td_us);
    for (int k = 0; k < cycles; ++k) step();
  }
  void step() {
    last = drill.update(ctx);
    ++ctx.cycle;
  }
  rt::BlockStatus last{rt::BlockStatus::kOk};  // the last update()'s status
};

}  // namespace edm::test
