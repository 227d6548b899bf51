#pragma once
// The inputs the linear and circular interpolators share (start edge, feed, override, hold and
// the position load), each wired to a test-owned output, and their busy/done outputs. The test's
// rig adds its own inputs, then calls h.start_ok(). Test code only: not RT-safe, not thread-safe.

#include "block_harness.hpp"

namespace edm::blocks {

template <class B>
struct InterpolatorRig {
  explicit InterpolatorRig(rt::Duration period) : h(period) {}
  [[nodiscard]] bool busy() const { return h.template out<bool>("busy"); }
  [[nodiscard]] bool done() const { return h.template out<bool>("done"); }
  /// Steps until the move is done, at most `limit` steps; returns the number of steps (the edge
  /// cycle not included).
  int run_to_end(int limit = 10'000'000) {
    int n = 0;
    while (busy() && n < limit) {
      h.step();
      ++n;
    }
    return n;
  }

  BlockHarness<B> h;
  rt::Output<bool>& start = h.template source<bool>("start");
  rt::Output<double>& feed = h.template source<double>("feed_mm_min");
  rt::Output<double>& ov = h.template source<double>("override");
  rt::Output<bool>& hold = h.template source<bool>("hold");
  rt::Output<bool>& load = h.template source<bool>("load");
  rt::Output<double>& load_x = h.template source<double>("load_x_mm");
  rt::Output<double>& load_y = h.template source<double>("load_y_mm");
};

}  // namespace edm::blocks
