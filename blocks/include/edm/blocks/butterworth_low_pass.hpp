#pragma once
// ButterworthLowPass: the 2nd-order digital Butterworth low-pass of seed 000 (Lee & Liao 2003,
// §3.2), which smooths the abnormal ratio Rab before the grey predictor.
//
// Cut-off: `cutoff` = Wn = fc / (fs/2), a fraction of the Nyquist frequency of the task that runs
// the block (the paper: "0.012 times one half of sampling frequency"; Table 2's column is
// 2·fc/fs; MATLAB's butter(2, Wn) uses the same convention). fs = 1/dt of the task, so the
// filter is defined per sample: on the paper's 40 ms task, 0.012 → fc = 0.15 Hz.
//
// Design: analogue prototype H(s) = 1/(s² + √2·s + 1), bilinear transform with pre-warping so
// that |H| = 1/√2 (−3 dB) exactly at Wn:
//   K  = tan(π·Wn/2),   D = 1 + √2·K + K²
//   b0 = K²/D,  b1 = 2·b0,  b2 = b0,   a1 = 2·(K² − 1)/D,   a2 = (1 − √2·K + K²)/D
//   y(k) = b0·x(k) + b1·x(k−1) + b2·x(k−2) − a1·y(k−1) − a2·y(k−2)        (direct form I)
// DC gain Σb/(1 + a1 + a2) = 1; |H(e^{jω})|² = 1 / (1 + (tan(ω/2)/K)⁴).
//
// Start: activate() puts the filter in steady state at `initial`. With `prime` (default) the
// first sample after activate() instead sets that steady state to the sample itself, so a
// filtered Rab starts at the measured value rather than rising from `initial` over ~1/Wn samples.
// A non-finite input leaves the state and out unchanged and returns kFault. Wn can be written at
// run time (coefficients recomputed, state kept).
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins.

#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct ButterworthLowPassParams {
  double cutoff{0.012};  // Wn = fc/(fs/2), in (0, 1) (seed 000: 0.012)
  double initial{0.0};   // steady state after activate() [signal unit]
  bool prime{true};      // the first sample after activate() sets the steady state

  void visit(rt::ParamVisitor& v) {
    v.param("cutoff", cutoff,
            {"1", "cut-off Wn as a fraction of the Nyquist frequency", rt::open(0.0, 1.0)});
    v.param("initial", initial,
            {"", "steady-state value after activation, signal unit", ranges::kSignal});
    v.param("prime", prime, {"", "the first sample after activation sets the steady state"});
  }
};

class ButterworthLowPass final : public rt::BlockWithParams<ButterworthLowPassParams> {
 public:
  struct Coefficients {
    double b0{1.0}, b1{0.0}, b2{0.0}, a1{0.0}, a2{0.0};
  };
  /// The coefficients for Wn (formulas above). Pure; Wn outside (0, 1) gives a pass-through.
  static Coefficients design(double wn) noexcept;
  /// Non-RT. Computes the coefficients.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. State and out = initial.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (state and out held) on a non-finite input.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  [[nodiscard]] const Coefficients& coefficients() const noexcept { return c_; }

 protected:
  void params_changed() noexcept override;

 private:
  void set_state(double v) noexcept;

  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
  Coefficients c_;
  double x1_{0.0}, x2_{0.0}, y1_{0.0}, y2_{0.0};
  bool primed_{false};
};

}  // namespace edm::blocks
