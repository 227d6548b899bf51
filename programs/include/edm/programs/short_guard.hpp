#pragma once
// The short-circuit handling DeepHoleDrill and WallFinish share (issue 19):
//   ShortLimits  their parameters: when the Td window reads short, and the retract budget;
//   ShortGuard   per cycle (step()): reads the window, drives and steps the retract child,
//                counts its retracts against the budget, raises alarm 150 when it is spent.
//
// Two readings (issue 31, DESIGN §11 "never a feed toward the work while the gap reads short"):
//   reads_short        the Td window: short_ratio ≥ short_ratio_limit. It takes ~window cycles to
//                      rise, and after retract.short_cycles of it the retract begins.
//   cycle_reads_short  this cycle's own pulses: td.cycle_short_ratio ≥ short_ratio_limit. A short
//                      shorter than the window (3-4 cycles of a fully shorted gap left the
//                      window at 0.29-0.49 while the drill fed down at up to 1 mm/s) stops the
//                      feed in that same cycle.
// Either one (the programs' short_now) stops every feed toward the work, and the retract child
// counts consecutive cycles of it: with the feed stopped at the first shorted cycle, the window
// alone may never fill at a persistent contact (the drill then sat at it, neither retracting
// nor raising alarm 150). The runtime's supervisor makes the
// same per-cycle stop on the process image for every program (machine.safety.short_stop,
// docs/safety.md); the programs make it too so that their own outputs, the wear estimate
// integrated from their command and the orbit's radius agree with what the axes do.
//
// RetractBudget: how many short retracts a cycle may make before alarm 150. A retract that
// follows progress (the retract child's tries back at 1: the hole or orbit advanced
// retract.progress_mm since the last one) starts the count again; more than `max` retracts
// without progress within `window` means a contact the retracts cannot clear.
// RT-safe (fixed storage, no allocation). Not thread-safe: the owning task.

#include <array>
#include <cstddef>
#include <cstdint>

#include "edm/blocks/short_retract.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/param.hpp"
#include "edm/runtime/time.hpp"

namespace edm::programs {

class RetractBudget {
 public:
  static constexpr std::int64_t kMaxRetracts = 16;

  /// A retract began at `now`; `tries` is the retract child's count since the last progress.
  /// True when this is one more than `max` (≤ kMaxRetracts) within `window`.
  bool exceeded(rt::TimePoint now, std::int64_t tries, std::int64_t max,
                rt::Duration window) noexcept {
    if (tries <= 1) {
      n_ = 0;
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < n_; ++k) {
      if (now - starts_[k] <= window) {
        starts_[kept++] = starts_[k];
      }
    }
    if (kept == starts_.size()) {  // full: forget the oldest (the count stays past any max)
      for (std::size_t k = 1; k < kept; ++k) {
        starts_[k - 1] = starts_[k];
      }
      --kept;
    }
    starts_[kept++] = now;
    n_ = kept;
    return static_cast<std::int64_t>(kept) > max;
  }
  [[nodiscard]] std::size_t count() const noexcept { return n_; }
  void reset() noexcept { n_ = 0; }

 private:
  std::array<rt::TimePoint, kMaxRetracts + 1> starts_{};
  std::size_t n_{0};
};

struct ShortLimits {
  double short_ratio_limit{0.9};       // the Td window reads short at this fraction of shorts
  std::int64_t short_retracts_max{3};  // retracts without progress allowed within the window
  rt::Duration short_retracts_window{std::chrono::seconds(10)};

  /// Declares the three parameters under their own names (a Params struct calls it).
  void visit(rt::ParamVisitor& v);
};

/// The short readings a cycle shows, declared in its pin table (as "gap_short", …).
struct ShortPins {
  explicit ShortPins(rt::PinTable& owner)
      : gap_short{owner, "gap_short"},
        short_retracts{owner, "short_retracts"},
        cycle_short{owner, "cycle_short"},
        short_now{owner, "short_now"} {}
  rt::Output<bool> gap_short;               // the Td window reads short (short_ratio ≥ the limit)
  rt::Output<std::int64_t> short_retracts;  // retracts in this cycle (hole, orbit)
  rt::Output<bool> cycle_short;  // this cycle's own pulses read short: nothing toward the work
  rt::Output<bool> short_now;    // gap_short || cycle_short: no feed; the retract counts it

  /// Not machining: no pulses of this cycle's, nothing reads short. RT-safe.
  void clear_now() noexcept {
    cycle_short.set(false);
    short_now.set(false);
  }
  /// A new cycle (hole, orbit) or activation: every reading and the count at 0. RT-safe.
  void reset() noexcept {
    gap_short.set(false);
    short_retracts.set(0);
    clear_now();
  }
};

/// What one cycle of ShortGuard::step() found (also shown on the cycle's ShortPins).
struct ShortStep {
  bool gap_short{false};      // the Td window reads short
  bool cycle_short{false};    // this cycle's own pulses read short
  bool short_now{false};      // either: no feed toward the work; the retract counts it
  bool retract_began{false};  // a retract began this cycle (count it)
  bool retracting{false};     // the retract child owns the command this cycle
  // The budget is spent. With a machine, alarm 150 is raised (its safe state follows); without
  // one (a unit test) the cycle must enter its own safe state: `status` is then kFault.
  bool budget_spent{false};
  rt::BlockStatus status{rt::BlockStatus::kOk};
};

class ShortGuard {
 public:
  enum class Event : std::uint8_t { kNone, kRetract, kBudgetSpent };

  /// One machining cycle of the short handling both cycles share (issue 32): reads the window
  /// and this cycle's pulses (shown on `pins`), drives the retract child's short_detected and
  /// enable (claimed by the owner's bind), steps it with `step_child` (the owner's
  /// CompositeBlock::step), counts a retract that began against the budget and, when it is spent,
  /// raises alarm 150 from `source` on `machine`. RT-safe.
  template <class StepChild>
  ShortStep step(const rt::CycleContext& ctx, const blocks::TdDetector& td,
                 blocks::ShortRetract& retract, const ShortLimits& p, rt::Machine* machine,
                 const char* source, ShortPins& pins, StepChild&& step_child) noexcept {
    ShortStep s;
    s.gap_short = reads_short(td, p);
    s.cycle_short = cycle_reads_short(td, p);
    s.short_now = s.gap_short || s.cycle_short;
    pins.gap_short.set(s.gap_short);
    pins.cycle_short.set(s.cycle_short);
    pins.short_now.set(s.short_now);
    retract.enable.drive(true);
    retract.short_detected.drive(s.short_now);
    s.status = step_child(retract);
    switch (after_retract_step(ctx.release, retract, p)) {
      case Event::kNone: break;
      case Event::kRetract:
        s.retract_began = true;
        pins.short_retracts.set(pins.short_retracts.get() + 1);
        break;
      case Event::kBudgetSpent:
        s.budget_spent = true;
        if (machine != nullptr) {
          raise_alarm(*machine, ctx.release, source);
        } else {
          s.status = rt::BlockStatus::kFault;
        }
        break;
    }
    s.retracting = retract.active.get();
    return s;
  }

  /// The window reads short: it holds a measurement and enough of it is shorts. RT-safe.
  [[nodiscard]] static bool reads_short(const blocks::TdDetector& td,
                                        const ShortLimits& p) noexcept {
    return td.valid.get() && td.short_ratio.get() >= p.short_ratio_limit;
  }
  /// This cycle's own pulses are shorted at the limit or beyond (td stepped this cycle). RT-safe.
  [[nodiscard]] static bool cycle_reads_short(const blocks::TdDetector& td,
                                              const ShortLimits& p) noexcept {
    return td.cycle_short_ratio.get() >= p.short_ratio_limit;
  }
  void reset() noexcept {
    budget_.reset();
    last_retracts_ = 0;
  }

 private:
  /// After the retract child's step: did a retract begin, and is the budget spent? RT-safe.
  Event after_retract_step(rt::TimePoint now, const blocks::ShortRetract& r,
                           const ShortLimits& p) noexcept {
    const std::int64_t started = r.retracts.get();
    if (started == last_retracts_) {
      return Event::kNone;
    }
    last_retracts_ = started;  // a retract began this cycle (also from RESUME)
    return budget_.exceeded(now, r.tries.get(), p.short_retracts_max, p.short_retracts_window)
               ? Event::kBudgetSpent
               : Event::kRetract;
  }
  /// Alarm 150 (a fault) from `source`. RT-safe.
  void raise_alarm(rt::Machine& m, rt::TimePoint now, const char* source) const noexcept {
    m.raise({rt::AlarmCode::kShortCircuit, rt::AlarmSeverity::kFault, now, source,
             "short circuit: too many retracts within the window",
             static_cast<double>(budget_.count())});
  }
  RetractBudget budget_;
  std::int64_t last_retracts_{0};
};

}  // namespace edm::programs
