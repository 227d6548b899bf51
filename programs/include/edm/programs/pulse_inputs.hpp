#pragma once
// PulseInputs: the generator's per-cycle pulse counters (the FPGA's, or the simulator's
// io.td_sum_ns, io.td_count, io.n_open, io.n_short) as inputs of a C++ PROGRAM, named as the
// TdDetector's inputs, and handed on to a child that has the same four inputs.
// The pins are listed in the owner's pin table. Non-RT: construction, feed() (bind time); the
// pins themselves are RT-safe.

#include <cstdint>

#include "edm/runtime/pin.hpp"

namespace edm::programs {

struct PulseInputs {
  explicit PulseInputs(rt::PinTable& owner)
      : td_sum_ns{owner, "td_sum_ns", "ns"},
        td_count{owner, "td_count"},
        n_open{owner, "n_open"},
        n_short{owner, "n_short"} {}

  rt::Input<std::int64_t> td_sum_ns;
  rt::Input<std::int64_t> td_count;
  rt::Input<std::int64_t> n_open;
  rt::Input<std::int64_t> n_short;

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
