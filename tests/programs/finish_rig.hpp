#pragma once
// WallFinish in a CompositeRig (composite_rig.hpp) with the inputs every finishing test drives —
// the electrode's X and Y and the start and final offsets — wired to outputs of the rig.

#include "composite_rig.hpp"
#include "edm/programs/wall_finish.hpp"

namespace edm::test {

struct FinishInputsRig : CompositeRig<programs::WallFinish> {
  rt::Output<double> x_mm, y_mm, start_offset, final_offset;

  using CompositeRig::CompositeRig;

  /// Configures the block as task cycle.finish, wires the inputs above and activates it.
  void configure_and_activate() {
    configure("cycle.finish");
    in<double>("x_mm").connect(x_mm);
    in<double>("y_mm").connect(y_mm);
    in<double>("start_offset_mm").connect(start_offset);
    in<double>("final_offset_mm").connect(final_offset);
    activate();
  }
};

}  // namespace edm::test
