#pragma once
// DischargeStateCounter: the discharge-state statistics circuit of seed 003 (Liu 2011, §1, Fig. 2).
//
// Three 32-bit shift registers R_open, R_normal, R_short remember the class of the last 32
// sampled pulses. Each pulse shifts every register left by one; a 1 enters bit D0 of the
// register of the pulse's class and a 0 enters the other two; the 33rd-oldest pulse drops out of
// D31. The counts are popcounts:
//
//   N_open = popcount(R_open),  N_normal = popcount(R_normal),  N_short = popcount(R_short)
//   N_open + N_normal + N_short = min(32, pulses seen since activate())          [pulses]
//
// The analysis interval m (LINT `interval`, ≥ 1) latches the three counts every m pulses (the
// paper's 锁存信号); the latched counts are the outputs and `data_ready` is true in each cycle in
// which at least one latch happened (the paper's data-ready flag, as a one-cycle pulse). m = 1
// latches after every pulse (newest pulse plus 31 old ones); m ≥ 32 makes every latched window
// consist only of pulses that arrived after the previous latch ("all-new pulses").
//
// Input mapping (choices; the paper samples one pulse at a time, a PLC cycle sees many):
// - Classes. The paper has open / normal / short (arcs are rare in EDM milling and left out).
//   The simulator also reports transient and stable arcs; with `arcs_as_short` (default) they are
//   counted as short (seed 000 lumps arcs with shorts as "abnormal"), otherwise as normal.
// - Order within a cycle. The cycle's T = o + n + s pulses (o open, n normal, s short incl. arcs)
//   are shifted in a fixed, evenly interleaved order: open pulses are spread over the T slots by
//   a centred Bresenham sequence, E(i; a, T) = ⌊(2·i·a + T) / (2T)⌋ open pulses among the first i,
//   and the remaining T − o slots are split between normal and short the same way. Every class
//   enters exactly its count (the sum invariant holds), any 32 consecutive pulses of one cycle
//   hold each class within ±2 of its proportional share, and the result depends on nothing but
//   the counts (deterministic). The class of pulse i is O(1), so a cycle costs at most two
//   32-pulse windows (the last latch of the cycle and the end of the cycle), whatever T is.
// - Latches inside a cycle. When several latches fall inside one cycle, the outputs show the
//   last one; `latches` says how many there were.
//
// Counters that are negative or above kMaxCount per cycle are a broken signal: nothing is
// shifted, the outputs are held and update() returns kFault.
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <cstdint>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct DischargeStateCounterParams {
  static constexpr std::int64_t kMaxInterval = std::int64_t{1} << 30;

  std::int64_t interval{32};  // analysis interval m [pulses], 1..kMaxInterval
  bool arcs_as_short{true};   // transient and stable arcs count as short (else as normal)

  void visit(rt::ParamVisitor& v) {
    v.param("interval", interval,
            {.unit = "pulses",
             .description = "analysis interval m: latch the counts every m pulses (>= 32: all-new "
                            "pulses)",
             .range = rt::closed(1.0, static_cast<double>(kMaxInterval))});
    v.param("arcs_as_short", arcs_as_short,
            {.unit = "",
             .description = "count transient and stable arcs as short pulses (false: as normal)"});
  }
};

class DischargeStateCounter final : public rt::BlockWithParams<DischargeStateCounterParams> {
 public:
  /// Register width and largest count (paper: 32-bit shift registers).
  static constexpr int kBits = 32;
  /// Per-cycle count above this is a broken signal (keeps 2·i·a in int64).
  static constexpr std::int64_t kMaxCount = std::int64_t{1} << 28;

  enum class PulseClass : std::uint8_t { kOpen, kNormal, kShort };
  /// Non-RT. Clears the registers and the outputs.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (nothing shifted, outputs held) on a broken counter.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  /// Class of pulse i (0-based) among the o + n + s pulses of one cycle, in the interleaved order
  /// described above. Pure, RT-safe; exposed for tests.
  static PulseClass pulse_class(std::int64_t i, std::int64_t o, std::int64_t n,
                                std::int64_t s) noexcept;

  /// The live registers (bit 0 = newest pulse). Owning thread only (tests, diagnostics).
  [[nodiscard]] std::uint32_t open_register() const noexcept { return reg_[0]; }
  [[nodiscard]] std::uint32_t normal_register() const noexcept { return reg_[1]; }
  [[nodiscard]] std::uint32_t short_register() const noexcept { return reg_[2]; }

 private:
  struct Regs {
    std::uint32_t r[3]{0, 0, 0};
  };
  // Registers after pulses 0..j of this cycle were shifted into `before`.
  static Regs shifted(const Regs& before, std::int64_t j, std::int64_t o, std::int64_t n,
                      std::int64_t s) noexcept;

  rt::Input<std::int64_t> n_open_{pins_, "n_open", "pulses"};
  rt::Input<std::int64_t> n_normal_{pins_, "n_normal", "pulses"};
  rt::Input<std::int64_t> n_short_{pins_, "n_short", "pulses"};
  rt::Input<std::int64_t> n_transient_arc_{pins_, "n_transient_arc", "pulses"};
  rt::Input<std::int64_t> n_stable_arc_{pins_, "n_stable_arc", "pulses"};
  rt::Output<std::int64_t> open_count_{pins_, "open_count", "pulses"};
  rt::Output<std::int64_t> normal_count_{pins_, "normal_count", "pulses"};
  rt::Output<std::int64_t> short_count_{pins_, "short_count", "pulses"};
  rt::Output<std::int64_t> latches_{pins_, "latches"};
  rt::Output<bool> data_ready_{pins_, "data_ready"};
  std::uint32_t reg_[3]{0, 0, 0};
  std::int64_t since_latch_{0};  // pulses since the last latch, < interval
};

}  // namespace edm::blocks
