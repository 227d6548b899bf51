#pragma once
// PulseInputs: the generator's per-cycle pulse counters (the FPGA's, or the simulator's
// io.td_sum_ns, io.td_count, io.n_open, io.n_short) as inputs of a C++ PROGRAM, named as the
// TdDetector's inputs, and handed on to a child that has the same four inputs.
// Non-RT: visit(), feed() (load and bind time); the pins themselves are RT-safe.

#include <cstdint>

#include "edm/runtime/pin.hpp"

namespace edm::programs {

struct PulseInputs {
  rt::Input<std::int64_t> td_sum_ns, td_count, n_open, n_short;

  void visit(rt::PinVisitor& v) {
    v.input("td_sum_ns", td_sum_ns, "ns");
    v.input("td_count", td_count);
    v.input("n_open", n_open);
    v.input("n_short", n_short);
  }
  /// `to`'s four counter inputs read these (a TdDetector, or another program's PulseInputs).
  template <class To>
  void feed(To& to) const noexcept {
    to.td_sum_ns.follow(td_sum_ns);
    to.td_count.follow(td_count);
    to.n_open.follow(n_open);
    to.n_short.follow(n_short);
  }
};

}  // namespace edm::programs
