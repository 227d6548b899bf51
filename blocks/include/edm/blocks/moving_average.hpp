#pragma once
// MovingAverage: the mean of the last `window` samples, O(1) per cycle.
//
//   out  = (x[n] + … + x[n−N+1]) / N   once N = window samples have been seen (full = true);
//   out  = mean of the n+1 samples seen so far before that (full = false).
//
// Accuracy (no drift): the running sum is kept as an unevaluated pair hi + lo updated with
// error-free TwoSum steps (Kahan–Babuška/Neumaier), so the bits lost when a large sample enters
// the sum come back out when it leaves. In addition a second compensated sum accumulates the
// samples of the current pass over the ring buffer and replaces the running sum each time the
// write index wraps, so rounding can never build up over more than one window. Cost: three
// TwoSum steps per cycle, no O(window) recomputation in any cycle (no jitter spike).
//
// `window` sizes the buffer, allocated once in configure(); it is load time only (a runtime
// write is refused: reload the config instead).
// A non-finite input is not stored: out and full are held and update() returns kFault; so is a
// window whose sum overflows.
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins (see
// pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/window_ring.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct MovingAverageParams {
  static constexpr std::int64_t kMaxWindow = 65536;

  std::int64_t window{16};  // samples, 1..kMaxWindow

  void visit(rt::ParamVisitor& v) {
    v.param("window", window,
            rt::load_time({"samples", "number of samples averaged",
                           rt::closed(1.0, static_cast<double>(kMaxWindow))}));
  }
};

class MovingAverage final : public rt::BlockWithParams<MovingAverageParams> {
 public:
  /// Non-RT. Allocates the ring buffer (window samples).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Empties the window: out = 0, full = false.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (out held) on a non-finite input or an overflowing sum.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  // hi + lo represents a sum more precisely than one double.
  struct CompensatedSum {
    double hi{0.0};
    double lo{0.0};
    void add(double x) noexcept;
    [[nodiscard]] double value() const noexcept { return hi + lo; }
  };

  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
  rt::Output<bool> full_{pins_, "full"};
  WindowRing<double> window_;  // allocated in configure(); its capacity is the window in use
  CompensatedSum sum_;         // running sum of the window
  CompensatedSum pass_sum_;    // sum of the samples pushed since the ring was last at slot 0
};

}  // namespace edm::blocks
