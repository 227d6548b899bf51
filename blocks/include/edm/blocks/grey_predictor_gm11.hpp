#pragma once
// GreyPredictorGM11: the GM(1,1) grey predictor of seed 000 (Lee & Liao 2003, eq. 1), which
// looks p samples ahead of the Butterworth-filtered Rab to cancel the filter's delay.
//
// Each cycle, over the last n samples x⁰(1)…x⁰(n) (x⁰(n) = this cycle's input):
//   AGO          x¹(k) = Σ_{i≤k} x⁰(i)
//   background   z(k)  = (x¹(k−1) + x¹(k)) / 2,                         k = 2…n
//   grey model   x⁰(k) + c·z(k) = b    (c: development coefficient, b: grey input)
//   least squares over k = 2…n, in centred form (well conditioned for slowly varying data):
//                c = −Σ(z−z̄)(x⁰−x̄) / Σ(z−z̄)²,   b = x̄ + c·z̄
//   prediction (eq. 1, the default, `paper_exp: true`), with y(0) = x⁰(1) the oldest sample:
//                x̂⁰(n+p) = (1 − e^c)·(x⁰(1) − b/c)·e^(−c·(n−1+p))
//                         = (b − c·x⁰(1))·expm1(c)/c·e^(−c·(n+p−1))   (no b/c: c = 0 is regular)
//   or (`paper_exp: false`, an option)
//                x̂⁰(n+p) = (b − c·x⁰(1))/(1 + c/2)·ρ^(n+p−2),   ρ = (1 − c/2)/(1 + c/2)
//
// The paper's eq. (1), ŷ(k+p) = (1 − e^c)(y(0) − b/c)·e^(−c(k+p)), is the whitened continuous
// solution of the fitted model; the option replaces e^(−c) by ρ, the exact solution of the fitted
// difference equation. The two agree to O(c³) per step for the slowly varying filtered Rab
// (|c| ≪ 1); only ρ makes the predictor exact on exponential sequences x⁰(k) = C·e^(αk) (the
// fit has zero residual there and ρ = e^α). Until issue 20 ρ was the default; the paper's form
// is now, and the wire benchmark (B6) measures both (docs/controllers.md).
//
// Outputs: out = x̂⁰(n+p) clamped to [out_min, out_max]; c and b of the fit; valid = true when
// out is a prediction. The clamp matters for a ratio such as Rab: on a start-up transient (the
// filtered Rab rising from 0) the fit sees explosive relative growth and x̂⁰ can reach 10³ or
// more; wire out_min = 0, out_max = 1 there.
// Degenerate windows (documented outputs, never NaN):
//   - fewer than n samples since activate(): out = the latest sample, valid = false;
//   - Σ(z−z̄)² = 0 (all zeros, or x⁰ alternating ±v): out = the latest sample, valid = false;
//   - all samples equal to v ≠ 0: c = 0, b = v, out = v exactly, valid = true;
//   - |c| ≥ 2 (ρ ≤ 0: the sequence is not exponential-like) or a non-finite prediction
//     (ρ^(n+p) overflow): out = the latest sample, valid = false.
// A non-finite input is not stored: outputs held, kFault.
// Cost O(n) per cycle. n sizes a ring allocated in configure() (load time only).
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/window_ring.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct GreyPredictorGM11Params {
  static constexpr std::int64_t kMaxWindow = 1024;
  static constexpr std::int64_t kMaxHorizon = 100000;

  std::int64_t window{5};    // n samples in the fit, 4..kMaxWindow (load time only)
  std::int64_t horizon{37};  // p samples ahead, 0..kMaxHorizon (seed 000: 37 at Wn = 0.012)
  bool paper_exp{true};      // eq. (1)'s e^(−c); false: the exact discrete ρ
  double out_min{-1e12};     // out is clamped to [out_min, out_max] (Rab: 0 and 1)
  double out_max{1e12};

  void visit(rt::ParamVisitor& v) {
    v.param("window", window,
            rt::load_time({"samples", "samples in the GM(1,1) fit",
                           rt::closed(4.0, static_cast<double>(kMaxWindow))}));
    v.param("horizon", horizon,
            {"samples", "prediction horizon p", rt::closed(0.0, static_cast<double>(kMaxHorizon))});
    v.param("paper_exp", paper_exp,
            {"", "true: exp(-c) of the paper's eq. 1; false: the exact discrete rho"});
    v.param("out_min", out_min, {"", "lower clamp of out (Rab: 0)", ranges::kSignal});
    v.param("out_max", out_max, {"", "upper clamp of out (Rab: 1), >= out_min", ranges::kSignal});
  }
  /// Cross-field rule: out_min <= out_max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class GreyPredictorGM11 final : public rt::BlockWithParams<GreyPredictorGM11Params> {
 public:
  /// Result of one fit and prediction over samples x[0..n−1] (oldest first). Pure, RT-safe.
  struct Fit {
    double c{0.0};
    double b{0.0};
    double prediction{0.0};
    bool valid{false};
  };
  static Fit predict(const double* x, std::size_t n, std::int64_t horizon, bool paper_exp) noexcept;
  /// Non-RT. Allocates the ring and the work buffer (window samples each).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Empties the window; out = c = b = 0, valid = false.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (nothing stored, outputs held) on a non-finite input.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  rt::Input<double> in_{pins_, "in"};
  rt::Output<double> out_{pins_, "out"};
  rt::Output<double> c_{pins_, "c", "1"};
  rt::Output<double> b_{pins_, "b"};
  rt::Output<bool> valid_{pins_, "valid"};
  WindowRing<double> window_;  // allocated in configure(); its capacity is n
  std::vector<double> work_;   // the window in chronological order
};

}  // namespace edm::blocks
