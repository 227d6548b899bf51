#pragma once
// IterativeLearningControl: the ILC of seed 002 (Furlan & Balemi, SUPSI) for cyclic machining in
// which the start of each cycle depends on the material removed before (die sinking: one jump
// cycle; orbiting: one revolution).
//
// Lifted domain over a cycle of N samples (vectors of length N, cycle index j):
//   process    z_j = P·u_j,  δ_j = z_j − z_p,j,  y_j = kδ·δ_j + b + n_j,
//              z_p,j+1 = z_A,j+1 + [0 1]·z_p,j      (the surface recedes by z_A per cycle)
//   law        u_j+1 = Q·(u_j + L·e_j),   e_j = y_ref − y_j
//              L·e = l1·(e − ē·1) + l2·ē·1 + l3·x_j·1,   ē = (1/N)·1ᵀ·e,   x_j+1 = x_j + ē_j
//   Q          first-sample-anchored low-pass: (Q·v)_0 = v_0, (Q·v)_i = v_0 + Σ_{m=1..i}
//              q_{i−m}·(v_m − v_0), with q_m = (1 − a)·a^m (first-order, pole a = q_pole), so
//              q0 = 1 − a and Q·(c·1) = c·1. a = 0 gives Q = I.
//   gains      (pole placement, eq. 1)  l1 = (q0 − λ3)/(kδ·q0·p0),  l2 = (2 − λ1 − λ2)/kδ,
//              l3 = (1 − λ1)(1 − λ2)/kδ
// λ1, λ2 are the poles of the cycle-mean (forward motion) dynamics: Q and P preserve constants,
// so the cycle means follow x_j+1 = x_j − kδ·δ̄_j, δ̄_j+1 = l3·x_j + (1 − kδ·l2)·δ̄_j (the
// paper's Φ restricted to constants), whose characteristic polynomial is (λ − λ1)(λ − λ2). λ3 sets
// the within-cycle dynamics: it is the diagonal of PQ(P⁻¹ − kδ·l1·I) below the anchored first
// sample (for P = Q = I the zero-mean part of a repeating error shape contracts by exactly λ3 per
// cycle).
//
// Sampling convention: at each update the block stores the error of the sample it output last
// update (y is the response to that output), then outputs u_j(k) for the current sample k. So p0
// is the first sample of the axis' impulse response as the block sees it (one task period after
// the command). A cycle ends at a rising edge of `cycle_start` (or every N samples when
// auto_cycle is set); a cycle cut short repeats its last error over the missing samples, a cycle
// longer than N holds u_j(N−1) and keeps overwriting e_j(N−1) (status kSaturated). Before the
// first cycle edge (without auto_cycle) the output is u_initial and nothing is learnt.
//
// Warm start (warm_cycles W > 0): another controller (the paper's integral controller) runs the
// first W complete cycles while this block records the position it applies (input `track`) as
// u_j, with the error e_j, and outputs u = track (`active` false: wire a Select's g to it). At
// the end of cycle W it learns u_j+1 = Q·(u_j + L·e_j) from the recorded cycle and takes over
// (`active` true). With W ≥ 2 it also starts the forward motion where the other controller left
// it: x = (mean(u_W) − mean(u_W−1))/l3, so that l3·x, the advance per cycle at zero mean error,
// equals the other controller's last advance per cycle. Without it, x = 0.
// Cost O(N) per cycle edge, O(1) otherwise. N sizes buffers allocated in configure().
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/rising_edge.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct IterativeLearningControlParams {
  static constexpr std::int64_t kMaxSamples = 65536;
  static constexpr double kMaxPole = 1.0 - 1e-9;  // |pole| bound: strictly inside the unit circle

  std::int64_t n_samples{100};  // N, samples per cycle, load time only
  double p0{0.5};               // first impulse-response sample of the closed axis loop
  double k_delta{1.0};          // kδ: output per unit of gap (y = kδ·δ + b), != 0
  double q_pole{0.0};           // a of Q's first-order low-pass, [0, 1); q0 = 1 − a
  double lambda1{0.5};          // forward-motion poles, (−1, 1)
  double lambda2{0.5};
  double lambda3{0.5};    // within-cycle pole, (−1, 1)
  double u_initial{0.0};  // u before learning and in the first cycle [position unit]
  double u_min{-1e9};     // clamp of u [position unit]
  double u_max{1e9};
  bool auto_cycle{false};       // the cycle ends every N samples without cycle_start
  std::int64_t warm_cycles{0};  // cycles another controller runs while u is recorded from track
  double e_max{0.0};            // > 0: each sample's error is clamped to ±e_max (0: off)

  void visit(rt::ParamVisitor& v) {
    v.param("n_samples", n_samples,
            rt::load_time({"samples", "samples per cycle N",
                           rt::closed(2.0, static_cast<double>(kMaxSamples))}));
    // Ranges (issue 31): model coefficients within ±1e6 (the sinking config: p0 0.005, k_delta
    // 1290), u and the error clamp in the position signal's unit, within ±1e12 (param_ranges.hpp).
    v.param("p0", p0,
            {"1", "first impulse-response sample of the axis loop, != 0", ranges::kCoefficient});
    v.param("k_delta", k_delta,
            {"", "output per unit of gap, y = k_delta*gap + b, != 0", ranges::kCoefficient});
    v.param("q_pole", q_pole,
            {"1", "pole a of the Q low-pass (0: no filter)", rt::closed(0.0, kMaxPole)});
    v.param("lambda1", lambda1, {"1", "forward-motion pole 1", rt::closed(-kMaxPole, kMaxPole)});
    v.param("lambda2", lambda2, {"1", "forward-motion pole 2", rt::closed(-kMaxPole, kMaxPole)});
    v.param("lambda3", lambda3, {"1", "within-cycle pole", rt::closed(-kMaxPole, kMaxPole)});
    v.param("u_initial", u_initial,
            {"", "output before learning, position unit, in [u_min, u_max]", ranges::kSignal});
    v.param("u_min", u_min, {"", "lower clamp of u", ranges::kSignal});
    v.param("u_max", u_max, {"", "upper clamp of u, >= u_min", ranges::kSignal});
    v.param("auto_cycle", auto_cycle, {"", "a cycle ends every n_samples without cycle_start"});
    v.param("warm_cycles", warm_cycles,
            rt::load_time({"cycles",
                           "complete cycles recorded from `track` before this block takes over (0: "
                           "none; the warm-up starts at activation)",
                           rt::closed(0.0, 1e6)}));
    v.param("e_max", e_max,
            {"",
             "> 0: clamp each sample's error to +-e_max, the range where y = k_delta*gap + b holds "
             "(0: off)",
             rt::closed(0.0, 1.0e12)});
  }
  /// Rules a range cannot say: p0 != 0, k_delta != 0, u_min <= u_initial <= u_max.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class IterativeLearningControl final : public rt::BlockWithParams<IterativeLearningControlParams> {
 public:
  struct Gains {
    double l1{0.0}, l2{0.0}, l3{0.0};
  };
  /// Eq. (1) of the paper. Pure, RT-safe.
  static Gains gains(const IterativeLearningControlParams& p) noexcept;
  /// Non-RT. Allocates u and e (N samples each).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. u = u_initial everywhere, x = 0, waiting for the first cycle edge.
  void activate() noexcept override;
  /// RT-safe.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  void learn() noexcept;

  /// End of a warm-up cycle: counts it; after the last one, learns from it and takes over.
  void end_warm_cycle() noexcept;

  rt::Input<double> y_{pins_, "y"};
  rt::Input<double> y_ref_{pins_, "y_ref"};
  rt::Input<double> track_{pins_, "track", "position unit"};
  rt::Input<bool> cycle_start_{pins_, "cycle_start"};
  rt::Input<bool> enable_{pins_, "enable", "", true};
  rt::Output<double> u_out_{pins_, "u"};
  rt::Output<double> mean_error_{pins_, "mean_error"};
  rt::Output<double> x_out_{pins_, "x"};
  rt::Output<double> l1_{pins_, "l1"};
  rt::Output<double> l2_{pins_, "l2"};
  rt::Output<double> l3_{pins_, "l3"};
  rt::Output<std::int64_t> sample_{pins_, "sample", "samples"};
  rt::Output<std::int64_t> cycles_{pins_, "cycles"};
  rt::Output<bool> active_{pins_, "active"};
  std::vector<double> u_;
  std::vector<double> e_;
  std::int64_t idx_{-1};  // sample output last update; −1 before the first cycle
  RisingEdge cycle_start_edge_;
  bool overrun_{false};
  double x_{0.0};
  double last_e_{0.0};
  std::int64_t cycles_done_{0};
  std::int64_t warm_done_{0};   // complete cycles recorded from track
  double prev_warm_mean_{0.0};  // mean of the previous recorded cycle's u
  bool warm_{false};            // recording from track (warm_done_ < warm_cycles)
};

}  // namespace edm::blocks
