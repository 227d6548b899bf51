#pragma once
// DischargeStateCounter: the discharge-state statistics circuit of seed 003 (Liu 2011, §1, Fig. 2).
//
// Three 32-bit shift registers R_open, R_normal, R_short remember the class of the last 32
// sampled pulses (bit 0 = newest pulse, the 33rd-oldest drops out of bit 31). The counts are
// popcounts:
//
//   N_open = popcount(R_open),  N_normal = popcount(R_normal),  N_short = popcount(R_short)
//   N_open + N_normal + N_short = min(32, pulses seen since activate())          [pulses]
//
// The registers are not rebuilt here: the block reads the generator's own last-32 class bitmasks
// (the simulator's io.hist_open, io.hist_short, io.hist_arc; bit 0 newest), which the plant shifts
// one bit per pulse exactly as the paper's registers do. From them:
//
//   R_open   = hist_open
//   R_short  = hist_short | hist_arc         (arcs_as_short, the default)  or  hist_short
//   R_normal = ~(hist_open | hist_short | hist_arc) (| hist_arc when arcs count as normal)
//
// each masked to the pulses seen since activate() (the paper's registers start cleared, so the
// three counts sum to 32 only once 32 pulses have been seen). The per-cycle pulse counters
// (n_open … n_stable_arc) are the paper's sampling signal: their sum T is the number of pulses
// that were shifted in this cycle, and it clocks the analysis interval.
//
// Analysis interval m (LINT `interval`, ≥ 1; the paper's 分析间隔数 and 锁存信号): the counts are
// latched when at least m pulses have been shifted in since the previous latch, and `data_ready`
// is true in the cycle of a latch (the paper's data-ready flag, as a one-cycle pulse).
// m ≥ 32 makes every latched window consist only of pulses that arrived after the previous latch
// (the paper's "all-new pulses").
//
// Deviation (the one a PLC cannot avoid): a PLC cycle sees many pulses (9 … 21, 14 on average,
// per 1 ms cycle under B1's fuzzy servo on the drill preset) and the bitmasks only at the cycle's
// end, so a latch falls at the end of
// the first cycle in which the m-th pulse since the previous latch arrived, not at that pulse:
// latches are at most one per cycle and m … m + T − 1 pulses apart. With m ≤ T the block latches
// every cycle with pulses (the paper's m = 1 behaviour: the newest pulses plus old ones).
//
// A broken signal — a bitmask outside 0 … 2³² − 1, two class bitmasks with a common bit (a pulse
// has one class), or a counter that is negative or above kMaxCount — shifts nothing, holds the
// outputs and makes update() return kFault.
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>

#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct DischargeStateCounterParams {
  static constexpr std::int64_t kMaxInterval = std::int64_t{1} << 30;

  std::int64_t interval{32};  // analysis interval m [pulses], 1..kMaxInterval
  bool arcs_as_short{true};   // transient and stable arcs count as short (else as normal)

  void visit(rt::ParamVisitor& v) {
    v.param("interval", interval,
            {"pulses",
             "analysis interval m: latch the counts once m pulses arrived since the last latch (>= "
             "32: all-new pulses)",
             rt::closed(1.0, static_cast<double>(kMaxInterval))});
    v.param("arcs_as_short", arcs_as_short,
            {"", "count transient and stable arcs as short pulses (false: as normal)"});
  }
};

class DischargeStateCounter final : public rt::BlockWithParams<DischargeStateCounterParams> {
 public:
  /// Register width and largest count (paper: 32-bit shift registers).
  static constexpr int kBits = 32;
  /// Per-cycle count above this is a broken signal.
  static constexpr std::int64_t kMaxCount = std::int64_t{1} << 28;

  /// Non-RT. Clears the registers, the pulse count and the outputs.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (nothing shifted, outputs held) on a broken signal.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  /// The live registers after the last update (bit 0 = newest pulse). Owning thread only.
  [[nodiscard]] std::uint32_t open_register() const noexcept { return reg_[0]; }
  [[nodiscard]] std::uint32_t normal_register() const noexcept { return reg_[1]; }
  [[nodiscard]] std::uint32_t short_register() const noexcept { return reg_[2]; }

 private:
  rt::Input<std::int64_t> hist_open_{pins_, "hist_open", "bitmask"};
  rt::Input<std::int64_t> hist_short_{pins_, "hist_short", "bitmask"};
  rt::Input<std::int64_t> hist_arc_{pins_, "hist_arc", "bitmask"};
  rt::Input<std::int64_t> n_open_{pins_, "n_open", "pulses"};
  rt::Input<std::int64_t> n_normal_{pins_, "n_normal", "pulses"};
  rt::Input<std::int64_t> n_short_{pins_, "n_short", "pulses"};
  rt::Input<std::int64_t> n_transient_arc_{pins_, "n_transient_arc", "pulses"};
  rt::Input<std::int64_t> n_stable_arc_{pins_, "n_stable_arc", "pulses"};
  rt::Output<std::int64_t> open_count_{pins_, "open_count", "pulses"};
  rt::Output<std::int64_t> normal_count_{pins_, "normal_count", "pulses"};
  rt::Output<std::int64_t> short_count_{pins_, "short_count", "pulses"};
  rt::Output<bool> data_ready_{pins_, "data_ready"};
  std::uint32_t reg_[3]{0, 0, 0};
  std::int64_t seen_{0};         // pulses since activate(), saturated at kBits
  std::int64_t since_latch_{0};  // pulses since the last latch, < interval
};

}  // namespace edm::blocks
