#pragma once
// The safety supervisor (DESIGN §11): owned by the runtime, configured in `machine.safety`, it
// supervises the process image — the I/O driver's pins — whatever programs run. Each cycle of
// the I/O task, after the programs and before the driver publishes the outputs:
//
//   check       electrode left <= margin_mm        → alarm 160 electrode_used_up, fault
//               wire_break pin true                → alarm 170 wire_break, fault
//               |x_cmd − x| > ferror(|v_cmd|)      → alarm 140 following_error, fault
//               x outside [min_mm, max_mm] by more than min_ferror_mm (the overshoot a drive
//                 may add to a commanded stop)      → alarm 141 soft_limit, fault
//   refuse      |v| > v_max_mm_s                   → clamped to ±v_max, alarm 141 warning
//               v that cannot stop inside the range → cut to the speed that stops at the limit
//                 (v·dt + v²/(2·a_max) <= distance left; 0 at or beyond it), alarm 141, fault
//               a non-finite v                     → 0 (no alarm: a broken wire is a block's)
//   short stop  this cycle's own pulses shorted at the limit or beyond:
//                 n_short ≥ limit · Σ pulses, Σ pulses > 0 (the counters the I/O driver latched
//                 for this cycle: the generator's FPGA, the simulator's io.n_*; a negative count
//                 is a broken signal and reads short too)
//                                                  → every axis with a `retract` direction is
//                 commanded nothing against it (toward the work): 0 or its retract, in this very
//                 cycle, whatever a program's window says or a force asks (DESIGN §11: never a
//                 feed toward the work while the gap reads short). No alarm: a short is the
//                 process's, the programs retract from it; counted (short_stopped_cycles()).
//   safe state  FAULT: every axis 0 except its `retract` direction (Z backs off), within the
//               limits above; ESTOP: every axis 0; the `generator` pins false — read from the
//               machine's state now, so a fault raised earlier in this very cycle already acts,
//               and whatever is forced (supervision ranks above a force: pin.hpp).
//
// The following-error limit grows with speed (LinuxCNC's FERROR/MIN_FERROR):
//   ferror(v) = min_ferror_mm + (ferror_mm − min_ferror_mm) · min(1, |v| / v_max_mm_s)
// where x_cmd, v_cmd integrate the supervised command through the axis's a_max_mm_s2 (the drive's
// trajectory generator); they restart from the actual position on the first cycle, in OFF and
// in FAULT/ESTOP, and when homing sets an axis's encoder (ManualControl::position_epoch()).
// They integrate up to the time the inputs were read (not the release): when cycles were omitted
// or the task woke late (a host that did not run it: 22–27 ms seen on a loaded VM), the drive
// went on at the last command until the inputs were read, and so does the model, in whole
// periods (else the actual position runs ahead of it by v·delay, a false following error). A
// gap over kLongestFollowedGap (1 s) is a pause, not a drive running on: the model restarts from
// the actual position.
//
// Referencing (issue 21): the range checks (141 outside, commands cut at the limits) apply to
// the axes ManualControl says are referenced (X, Y, Z by name; an axis of another name always
// counts as referenced). An unreferenced axis's coordinates are those of its power-on position,
// so limits in them mean nothing; v_max and the following error still apply (LinuxCNC does the
// same for unhomed joints).
//
// Alarms: source "safety.<axis>" (140, 141), "safety.<axis>.v_max" (141 warning),
// "safety.electrode" (160), "safety.wire" (170). Each is raised every cycle its condition holds
// — the machine latches it, so that is one alarm, counted — and cleared when the condition is
// gone, so a later occurrence is raised again.
//
// RT-safety: supervise() never allocates, locks, logs or throws. Thread-safety: built on the
// controlling thread; supervise() runs on the I/O task's thread only; the counters may be read
// from any thread.

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/manual.hpp"
#include "edm/runtime/pin.hpp"

namespace edm::rt {

/// One supervised axis, resolved to the driver's pins by the runtime builder.
struct SupervisedAxis {
  machining::AxisLimits limits;             // range, v_max, a_max
  Input<double>* velocity{nullptr};         // %Q: the command, mm/s
  const Output<double>* position{nullptr};  // %I: the actual position, mm
  double ferror_mm{0.0};                    // 0: no following-error check
  double min_ferror_mm{0.0};
  RetractDirection retract{RetractDirection::kNone};
};

/// Everything the supervisor watches and drives (pointers into the I/O driver).
struct SupervisorSetup {
  std::vector<SupervisedAxis> axes;
  const Output<double>* electrode_mm{nullptr};
  double electrode_margin_mm{0.0};
  const Output<bool>* wire_broken{nullptr};
  std::vector<Input<bool>*> generator;
  const ManualControl* manual{nullptr};  // referenced axes and position epoch; null: all referenced
  // The same-cycle short stop (machine.safety.short_stop); short_count null: none.
  const Output<std::int64_t>* short_count{nullptr};
  std::vector<const Output<std::int64_t>*> pulse_counts;  // their sum: all pulses of the cycle
  double short_limit{0.9};                                // (0, 1]
};

class Supervisor {
 public:
  /// Non-RT. `period` is the I/O task's interval.
  Supervisor(Machine& machine, SupervisorSetup setup, Duration period);
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// One cycle: checks, refusals and the safe state, written into the driver's input pins
  /// before write_outputs(). `inputs_at`: when the driver read this cycle's inputs (the task's
  /// clock at the cycle's start; the release on the virtual clock). RT-safe.
  void supervise(const CycleContext& ctx, TimePoint inputs_at) noexcept;
  void supervise(const CycleContext& ctx) noexcept { supervise(ctx, ctx.release); }

  /// Cycles in which a command was cut at a soft limit (position or speed). Any thread.
  [[nodiscard]] std::uint64_t refused_cycles() const noexcept {
    return refused_cycles_.load(std::memory_order_relaxed);
  }
  /// The latest |x_cmd − x| of axis k, mm (0 while not tracking). Any thread.
  [[nodiscard]] double following_error_mm(std::size_t k) const noexcept {
    return k < axes_.size() ? axes_[k].ferror_now_mm.load(std::memory_order_relaxed) : 0.0;
  }
  [[nodiscard]] std::size_t axis_count() const noexcept { return axes_.size(); }
  /// Cycles that read short (the short stop's condition held). Any thread.
  [[nodiscard]] std::uint64_t short_cycles() const noexcept {
    return short_cycles_.load(std::memory_order_relaxed);
  }
  /// Cycles in which the short stop cut a command toward the work. Any thread.
  [[nodiscard]] std::uint64_t short_stopped_cycles() const noexcept {
    return short_stopped_cycles_.load(std::memory_order_relaxed);
  }

 private:
  struct Axis {
    SupervisedAxis cfg;
    int ref_bit{-1};           // bit of ManualControl::referenced(); -1: always referenced
    std::string source;        // "safety.X"
    std::string speed_source;  // "safety.X.v_max"
    bool tracking{false};      // the commanded-position model is running
    double x_cmd_mm{0.0};
    double v_cmd_mm_s{0.0};
    double v_target_mm_s{0.0};  // the command published last cycle (what the drive follows)
    bool ferror_raised{false};
    bool limit_raised{false};
    bool speed_raised{false};
    std::atomic<double> ferror_now_mm{0.0};
  };

  [[nodiscard]] bool is_outside(const Axis& a, double x) const noexcept;
  [[nodiscard]] bool referenced(const Axis& a) const noexcept;
  void check_machine(TimePoint now) noexcept;
  /// This cycle's own pulses are shorted at the limit or beyond (short_stop configured).
  [[nodiscard]] bool cycle_reads_short() const noexcept;
  void check_axis(Axis& a, TimePoint now, bool track) noexcept;
  /// The command after the speed and range limits; raises/clears 141.
  double limit_command(Axis& a, TimePoint now) noexcept;
  /// One period of the commanded-position model towards the command v (a_max-limited).
  void advance_model(Axis& a, double v) const noexcept;
  /// How many periods the models are behind inputs read at `inputs_at` (rounded): 0 normally,
  /// n after n omitted cycles or a wake-up n periods late, -1 when the inputs came a period
  /// early (the cycle after a late one), -2 after a gap over kLongestFollowedGap (a pause).
  [[nodiscard]] std::int64_t periods_behind(TimePoint inputs_at) noexcept;
  /// `cycles` omitted periods of the model at the last published command (bounded work).
  void follow_omitted(Axis& a, std::int64_t cycles) const noexcept;

  static constexpr Duration kLongestFollowedGap = std::chrono::seconds(1);
  /// Raises `code` while `active`, clears it when it ends; `raised` remembers which.
  void condition(bool active, bool& raised, const Alarm& alarm) noexcept;

  Machine& machine_;
  std::vector<Axis> axes_;       // sized once in the constructor: sources stay put
  std::vector<double> command_;  // per axis, this cycle (preallocated)
  const Output<double>* electrode_mm_;
  double electrode_margin_mm_;
  const Output<bool>* wire_broken_;
  std::vector<Input<bool>*> generator_;
  const ManualControl* manual_;
  const Output<std::int64_t>* short_count_;
  std::vector<const Output<std::int64_t>*> pulse_counts_;
  double short_limit_;
  std::uint64_t epoch_seen_{0};
  Duration period_;
  double dt_s_;
  TimePoint model_at_{};  // when the inputs the models stand for are read (next cycle's)
  bool have_model_time_{false};
  bool electrode_raised_{false};
  bool wire_raised_{false};
  std::atomic<std::uint64_t> refused_cycles_{0};
  std::atomic<std::uint64_t> short_cycles_{0};
  std::atomic<std::uint64_t> short_stopped_cycles_{0};
};

}  // namespace edm::rt
