#pragma once
// The offline choice of the grey predictor's horizon p for a Butterworth cut-off Wn (seed 000,
// Lee & Liao 2003, §3.2 and Table 2), shared by edm-greyhorizon and its test.
//
// For a recorded signal x(0..N−1) (Rab sampled at the PLC period):
//   filtered   f = ButterworthLowPass::design(Wn) applied to x, started in steady state at x(0)
//   objective  o(k) = mean of x(k−L+1+s … k+s), L = 50, s = 25: the 50-step moving average
//              shifted 25 steps back, i.e. centred on k + 0.5 (needs 25 future samples)
//   prediction r_p(k) = GM(1,1) over f(k−n+1 … k) (n = 5), p steps ahead (eq. 1, or the ρ form
//              with paper_exp = false: the block's two forms), clamped to
//              [out_min, out_max]; the latest f(k) where the fit is not valid (as the block)
//   error      RMS over k of r_p(k) − o(k): the value the controller uses at time k against the
//              best non-causal estimate of the signal at time k
// and p is the argmin over 0 … max_horizon. The set of k is the same for every p: k ≥ warmup,
// k ≥ n − 1 and k + s < N.
//
// On a ramp x(k) = a + s·k the filter lags by its DC group delay τ = 1/(√2·K), K = tan(π·Wn/2)
// (exactly, after the transient), the objective has no lag (centre k + 0.5) and GM(1,1)
// extrapolates a slow ramp almost linearly, so the chosen p is the integer nearest τ + 0.5.

#include <cstddef>
#include <vector>

namespace edm::greyhorizon {

struct HorizonOptions {
  std::size_t window{5};        // n samples in the GM(1,1) fit (the block's default)
  std::size_t max_horizon{60};  // p = 0 … max_horizon
  std::size_t ma_length{50};    // L of the objective's moving average
  std::size_t ma_shift{25};     // s: the average is shifted s steps back (centred)
  std::size_t warmup{300};      // samples skipped before scoring (filter transient)
  double out_min{0.0};          // the prediction's clamp (Rab: 0 … 1, as wired in the bench)
  double out_max{1.0};
  bool paper_exp{true};  // the predictor's form: eq. 1's e^(−c) (the block's default) or ρ
};

struct HorizonResult {
  double wn{0.0};
  std::vector<double> rms;  // rms[p], p = 0 … max_horizon
  std::size_t best_p{0};
  double best_rms{0.0};
  std::size_t scored{0};  // samples in the RMS
};

/// The DC group delay of the 2nd-order bilinear Butterworth low-pass [samples]: 1/(√2·tan(πWn/2)).
double butterworth_dc_delay(double wn);

/// x filtered by ButterworthLowPass::design(wn), in steady state at x[0] before the first sample.
std::vector<double> butterworth_filter(const std::vector<double>& x, double wn);

/// o(k) = mean of x(k−L+1+s … k+s); NaN where the window leaves the record.
std::vector<double> shifted_moving_average(const std::vector<double>& x, std::size_t length,
                                           std::size_t shift);

/// The RMS error for every p and the best p (ties: the smaller p). Throws std::invalid_argument
/// when the record leaves nothing to score.
HorizonResult choose_horizon(const std::vector<double>& x, double wn, const HorizonOptions& opt);

/// Pools results of the same Wn over several records: RMS² weighted by each record's scored
/// samples, then the argmin again (ties: the smaller p). Throws std::invalid_argument on an
/// empty list or on results of different lengths.
HorizonResult pool_horizons(const std::vector<HorizonResult>& results);

}  // namespace edm::greyhorizon
