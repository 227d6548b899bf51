#pragma once
// ManualMotion: the operator's motion modes (DESIGN §12, issue 21) — reference (homing), jog
// (continuous with a dead-man, incremental) and touch-off by electrical contact — as a child of
// the job sequencer EdmJob (`<job>.manual`), which runs it while the machine is READY and no job
// is active (input `enable`) and hands it the axes while it is `active`. Requests arrive through
// rt::ManualControl (the bridge's home / jog / jog.stop / touch ops); state and results go back
// the same way. The runtime's safety supervisor watches every move like any other (soft limits
// of referenced axes, v_max, following error); an E-stop or fault ends the operation.
//
// Motion: one axis moves at a time along a reference with a trapezoidal speed profile
// (accel_mm_s2); the axis command is v_ref + kp·(ref − actual); the other axes hold where they
// were.
//
// Jog
//   distance  |d| in [0.001, 10] mm; on a referenced axis the target must lie inside the soft
//             limits (else kSoftLimit, nothing moves). Done when the reference arrives.
//   velocity  |v| ≤ jog_v_max_mm_s; moves toward the soft limit (referenced) or up to
//             home_search_max_mm (unreferenced) and stops there. Every new request refreshes it;
//             with none for `deadman` the axis decelerates to a stop (result kDeadman) — a dead
//             or hung client never keeps an axis moving. Velocity 0 or jog.stop stops it.
// Home (axes in home_order, e.g. "ZXY", those requested): per axis
//   off      if the switch reads on: move − at home_search_mm_s until it reads off;
//   search   move + at home_search_mm_s until the switch trips (at most home_search_max_mm:
//            else kNoSwitch) and stop;
//   back     move − by home_back_off_mm (the switch must read off);
//   latch    move + at home_latch_mm_s until it trips: stop at once and set the encoder so it
//            reads home_<axis>_mm there (outputs pos_set_<a> for one cycle, pos_value_<a>_mm);
//   settle   two cycles still, the axis is referenced (ManualControl), the position epoch moves
//            (the supervisor restarts its following-error model from the new reading).
// Touch (output touch_mode on throughout: the generator's sensing voltage, no discharge)
//   one side (z: −Z; x+: +X; x−: −X; y+, y−): if the contact reads on already → kAlreadyInContact;
//   fast  move toward the work at touch_fast_mm_s until contact (at most touch_max_mm: else
//         kNoContact, and back to the start), stop at once;
//   back  move away by touch_back_off_mm (the contact must read off);
//   slow  move toward it at touch_slow_mm_s until contact: the position of that cycle is the
//         touch; stop at once (the axis stops within touch_slow_mm_s · one cycle of contact);
//   off   move away by touch_back_off_mm.
//   Result: z → the axis Z at contact (the electrode tip on the surface); x+ → X + r, x− → X − r,
//   y± likewise (r = electrode_d_mm / 2: the edge's coordinate).
//   center (from inside a bore): x+ and x− from the start point, back to the start between them,
//   then to the X centre (the mean of the two contacts); y+ and y− likewise; result the centre
//   and the X diameter (size). Every touch ends back at its start (center: at the centre).
// An operation ends with a ManualResult (ok, error, values); the outputs return to zero.
//
// Parameters (`<job>.manual.*`, YAML under the job's params: `manual: {deadman: 300ms}`) and
// pins are listed in docs/blocks.md. RT-safety: update() never allocates, locks or throws.

#include <cstdint>

#include "edm/runtime/block.hpp"
#include "edm/runtime/manual.hpp"
#include "edm/runtime/xyz_pins.hpp"

namespace edm::machining {
struct MachineTables;
}

namespace edm::programs {

struct ManualMotionParams {
  double jog_v_max_mm_s{5.0};  // [mm/s]
  double accel_mm_s2{200.0};   // [mm/s²]
  double kp_per_s{20.0};       // [1/s]
  rt::Duration deadman{std::chrono::milliseconds(500)};
  std::string home_order{"ZXY"};
  double home_search_mm_s{5.0};      // [mm/s]
  double home_latch_mm_s{0.2};       // [mm/s]
  double home_back_off_mm{1.0};      // [mm]
  double home_search_max_mm{300.0};  // [mm]
  double home_x_mm{90.0};            // [mm] the machine coordinate of each reference switch
  double home_y_mm{90.0};
  double home_z_mm{15.0};
  double touch_fast_mm_s{1.0};    // [mm/s]
  double touch_slow_mm_s{0.05};   // [mm/s]
  double touch_max_mm{20.0};      // [mm]
  double touch_back_off_mm{0.2};  // [mm]
  double electrode_d_mm{1.0};     // [mm]
  bool reference_required{false};
  bool referenced_at_start{true};  // absolute encoders: every axis is referenced at power-on

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class ManualMotion final : public rt::BlockWithParams<ManualMotionParams, rt::Block> {
 public:
  rt::Input<bool> enable{pins_, "enable"};  // READY and no job: the sequencer gives the axes
  rt::Xyz<rt::Input<double>> pos{pins_, {"x_mm", "y_mm", "z_mm"}, "mm"};
  // Reference switches (wired: homing available).
  rt::Xyz<rt::Input<bool>> ref{pins_, {"ref_x", "ref_y", "ref_z"}};
  rt::Input<bool> contact{pins_, "contact"};     // touch sensing (wired: touch available)
  rt::Output<bool> active{pins_, "active"};      // moving the axes: the sequencer passes vx/vy/vz
  rt::Output<std::int64_t> mode{pins_, "mode"};  // rt::ManualMode
  rt::Xyz<rt::Output<double>> v_cmd{pins_, {"vx_cmd_mm_s", "vy_cmd_mm_s", "vz_cmd_mm_s"}, "mm/s"};
  rt::Output<bool> touch_mode{pins_, "touch_mode"};
  rt::Xyz<rt::Output<bool>> pos_set{pins_, {"pos_set_x", "pos_set_y", "pos_set_z"}};
  rt::Xyz<rt::Output<double>> pos_value{
      pins_, {"pos_value_x_mm", "pos_value_y_mm", "pos_value_z_mm"}, "mm"};
  rt::Output<std::int64_t> referenced{pins_, "referenced"};  // mask: bit 0 X, 1 Y, 2 Z

  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  void bind() override;
  void activate() noexcept override;
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  // The job's own touch (EdmJob's depth probe, issue 20 f): a −Z touch (fast, back, slow, off,
  // back to the start) from where the axes stand, run while `enable` is false (a job runs). It
  // moves the axes (`active`) and reports like an operator's touch, except that its result is
  // read here, not through ManualControl; an operator's request meanwhile is answered
  // kInterrupted. RT-safe.
  /// Starts it; false (nothing starts) when an operation runs or touch sensing is not wired.
  bool begin_job_touch_z(const rt::CycleContext& ctx) noexcept;
  /// Ends the job's touch at once (the job was stopped): the axes stop, touch mode off.
  void abort_job_touch() noexcept;
  /// True from begin_job_touch_z() until the touch has ended (back at its start, in position).
  [[nodiscard]] bool job_touch_busy() const noexcept { return job_op_; }
  /// The last job touch: whether it found the work, and the axis Z at the contact.
  [[nodiscard]] bool job_touch_ok() const noexcept { return job_ok_; }
  [[nodiscard]] double job_touch_z_mm() const noexcept { return job_z_mm_; }

 private:
  enum class Step : std::uint8_t {
    kIdle,
    kJog,      // a distance or velocity jog
    kHomeOff,  // leave the switch
    kHomeSearch,
    kHomeBack,
    kHomeLatch,
    kHomeSettle,
    kTouchArm,  // touch mode on, waiting for the first contact reading
    kTouchFast,
    kTouchBack,
    kTouchSlow,
    kTouchOff,
    kReturn,      // back to the start point (no contact, centre-finding)
    kCentre,      // to the centre of the two contacts
    kInPosition,  // the reference has arrived: waiting for the axes to settle on it
  };
  /// One axis's reference: a trapezoidal move to `target` at `speed`.
  struct Profile {
    double pos{0.0}, vel{0.0};
    double target{0.0}, speed{0.0};
    bool done{true};
  };

  void start(const rt::ManualRequest& r, const rt::CycleContext& ctx) noexcept;
  void finish(bool ok, rt::ManualError e, const rt::CycleContext& ctx) noexcept;
  /// The result of the operation (request `req_`) and the idle state, published next.
  void end_operation(bool ok, rt::ManualError e, double t_s) noexcept;
  void stop_outputs() noexcept;  // not active, touch mode off, every axis command 0
  /// finish() once the axes stand on their references (kInPosition).
  void finish_settled(bool ok, rt::ManualError e, const rt::CycleContext& ctx) noexcept;
  void begin_move(int axis, double target, double speed) noexcept;
  void stop_now() noexcept;  // the reference stops where the axis is
  void step_profile(double dt) noexcept;
  void command_axes() noexcept;
  [[nodiscard]] double axis_mm(int axis) const noexcept;  // pos[axis]
  [[nodiscard]] bool switch_on(int axis) const noexcept;
  [[nodiscard]] bool any_switch_wired() const noexcept;  // homing is available
  [[nodiscard]] bool is_referenced(int axis) const noexcept;
  [[nodiscard]] bool limits(int axis, double& lo, double& hi) const noexcept;
  /// One cycle of the running operation's steps (manual_motion_steps.cpp).
  void advance(const rt::CycleContext& ctx) noexcept;
  void next_home_axis(const rt::CycleContext& ctx) noexcept;
  void next_touch(const rt::CycleContext& ctx) noexcept;  // the next side (center) or the end
  void begin_touch_side() noexcept;
  void publish() noexcept;

  rt::ManualControl* manual_{nullptr};
  const machining::MachineTables* tables_{nullptr};
  double dt_s_{0.001};
  std::uint64_t last_seq_{0};
  rt::ManualStatus status_{};

  Step step_{Step::kIdle};
  rt::ManualRequest req_{};
  int axis_{0};  // the axis moving
  Profile prof_{};
  double hold_[3]{};   // where the other axes stay
  double start_[3]{};  // where the operation began (touch: its side's start)
  double travel_from_{0.0};
  rt::TimePoint refreshed_{};
  int settle_cycles_{0};
  rt::TimePoint settle_until_{};
  bool pending_ok_{false};
  rt::ManualError pending_error_{rt::ManualError::kNone};
  // Home.
  std::uint8_t home_todo_{0};  // axes left to reference
  std::size_t home_next_{0};   // index into home_order
  // Touch.
  int side_{0};         // +1 / −1: the direction toward the work
  int touch_index_{0};  // center: 0 x+, 1 x−, 2 y+, 3 y−
  double contact_[4]{};
  double found_{0.0};
  // The job's touch.
  bool job_op_{false};
  bool job_ok_{false};
  double job_z_mm_{0.0};
};

}  // namespace edm::programs
