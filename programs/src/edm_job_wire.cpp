#include "edm/programs/edm_job.hpp"

// EdmJob's wire-machine blocks: a cut along the path (the wire child) and the program stops
// M00/M01. The sequencer itself is edm_job.cpp.

#include "edm/runtime/machine.hpp"

namespace edm::programs {

bool EdmJob::run_cut(const machining::MotionBlock& b, const rt::CycleContext& ctx,
                     bool hold) noexcept {
  if (step_ == Step::kEnter) {
    set_move_from();
    wire_.begin(b, move_from_x_, move_from_y_, cut_continuing_);
    step_ = Step::kBusy;
  }
  const std::int64_t n_short = pulses.n_short.get();
  const std::int64_t n =
      pulses.n_open.get() + n_normal.get() + n_transient_arc.get() + n_stable_arc.get() + n_short;
  const double cap = (b.feed_mm_s > 0.0 ? b.feed_mm_s : params_.feed_default_mm_s) * feed_override_;
  const double u_ref = condition_ != nullptr ? condition_->servo_ref_v : 0.0;
  const bool done = wire_.step(ctx.dt_s, gap_voltage_v.get(), u_ref, n_short, n, cap, hold);
  set_reference(wire_.ref_x(), wire_.ref_y(), hold_z_, wire_.v_x(), wire_.v_y(), 0.0);
  hold_x_ = wire_.ref_x();
  hold_y_ = wire_.ref_y();
  cutting_ = !hold && condition_ != nullptr;
  if (done) cut_continuing_ = true;
  return done;
}

bool EdmJob::run_program_stop(const rt::CycleContext& ctx) noexcept {
  hold_position();
  if (step_ == Step::kEnter) {
    gen_on.set(false);
    machine_->command(rt::MachineCommand::kHold, ctx.release);
    step_ = Step::kBusy;
    return false;
  }
  return true;  // the next block waits while the machine holds
}

}  // namespace edm::programs
