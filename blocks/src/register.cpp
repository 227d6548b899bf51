#include "edm/blocks/register.hpp"

#include "edm/blocks/butterworth_low_pass.hpp"
#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/discharge_state_counter.hpp"
#include "edm/blocks/fuzzy_servo_lut.hpp"
#include "edm/blocks/gain.hpp"
#include "edm/blocks/gap_controller_p.hpp"
#include "edm/blocks/grey_predictor_gm11.hpp"
#include "edm/blocks/integrator.hpp"
#include "edm/blocks/iterative_learning_control.hpp"
#include "edm/blocks/jump_cycle.hpp"
#include "edm/blocks/limiter.hpp"
#include "edm/blocks/linear_interpolator.hpp"
#include "edm/blocks/low_pass.hpp"
#include "edm/blocks/moving_average.hpp"
#include "edm/blocks/orbit_expander.hpp"
#include "edm/blocks/polarity_switch.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/recursive_least_squares.hpp"
#include "edm/blocks/select.hpp"
#include "edm/blocks/self_tuning_fuzzy_pi.hpp"
#include "edm/blocks/self_tuning_regulator.hpp"
#include "edm/blocks/short_retract.hpp"
#include "edm/blocks/sine_source.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/blocks/wear_compensator.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

void register_builtin_blocks(rt::BlockRegistry& r) {
  r.add<Gain>("Gain", "out = k·in + offset");
  r.add<LowPass>("LowPass", "first-order low-pass filter (exact zero-order-hold discretisation)");
  r.add<Limiter>("Limiter", "clamp to [min, max] with an optional slew-rate limit");
  r.add<MovingAverage>("MovingAverage", "mean of the last `window` samples, O(1) per cycle");
  r.add<SineSource>("SineSource", "sine test signal, phase exact from the cycle count");
  r.add<Select>("Select", "IEC SEL of two signals with a bumpless (ramped) transfer");
  r.add<Integrator>("Integrator", "integrator with clamping anti-windup and reset");
  // Seed 004: deep-hole drilling.
  r.add<TdDetector>("TdDetector", "mean ignition delay and open/short ratios over a window");
  r.add<GapControllerP>("GapControllerP", "seed 004 eq. 1: Vz = Kg·(Tdr − Td), limits, retract");
  r.add<PolaritySwitch>("PolaritySwitch", "reverses polarity only with the generator off");
  r.add<WearCompensator>("WearCompensator", "seed 004 eq. 8: Vd = MRRe/A added to the Z feed");
  r.add<PositionLoop>("PositionLoop", "P/PI axis loop with feed-forward and following error");
  r.add<ShortRetract>("ShortRetract", "sustained short: retract along the path, resume, alarm");
  r.add<LinearInterpolator>("LinearInterpolator", "seed 004 eq. 12-13, exact end point");
  r.add<CircularInterpolator>("CircularInterpolator", "seed 004 eq. 14-19, G02/G03, full circles");
  r.add<OrbitExpander>("OrbitExpander", "seed 004 eq. 20-21: radius += kr·mean Td per revolution");
  // Die sinking: the periodic flushing jump (one jump cycle = one cycle of seed 002's ILC).
  r.add<JumpCycle>("JumpCycle", "periodic electrode jump of die sinking; cycle edges, held z");
  // Seed 003: discharge-state statistics and the fuzzy servo lookup table.
  r.add<DischargeStateCounter>("DischargeStateCounter",
                               "seed 003: open/normal/short counts of the last 32 pulses, latched");
  r.add<FuzzyServoLUT>("FuzzyServoLUT",
                       "seed 003: Mamdani servo surface precomputed into a 33x33 lookup table");
  // Seed 000: wire-EDM rupture prevention (Rab filter, grey predictor, self-tuning fuzzy PI).
  r.add<ButterworthLowPass>("ButterworthLowPass",
                            "seed 000: 2nd-order Butterworth low-pass, cut-off Wn of Nyquist");
  r.add<GreyPredictorGM11>("GreyPredictorGM11", "seed 000 eq. 1: GM(1,1) prediction p steps ahead");
  r.add<SelfTuningFuzzyPI>(
      "SelfTuningFuzzyPI",
      "seed 000 eq. 3-9: self-tuning fuzzy PI on Rab -> arc-off time, servo V");
  // Seed 001: self-tuning regulator of die sinking (RLS with forgetting, minimum variance).
  r.add<RecursiveLeastSquares>("RecursiveLeastSquares",
                               "seed 001: RLS with forgetting factor and covariance bound");
  r.add<SelfTuningRegulator>(
      "SelfTuningRegulator",
      "seed 001: minimum-variance STR, y_v -> servo reference V, y_t -> pulse-off time");
  // Seed 002: iterative learning control over the machining cycle.
  r.add<IterativeLearningControl>(
      "IterativeLearningControl",
      "seed 002: lifted-domain ILC, Q filter, l1/l2/l3 by pole placement, per jump/orbit cycle");
}

}  // namespace edm::blocks
