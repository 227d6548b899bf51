#include "edm/blocks/register.hpp"

#include "edm/blocks/gain.hpp"
#include "edm/blocks/integrator.hpp"
#include "edm/blocks/limiter.hpp"
#include "edm/blocks/low_pass.hpp"
#include "edm/blocks/moving_average.hpp"
#include "edm/blocks/sine_source.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

void register_builtin_blocks(rt::BlockRegistry& r) {
  r.add<Gain>("Gain", "out = k·in + offset");
  r.add<LowPass>("LowPass", "first-order low-pass filter (exact zero-order-hold discretisation)");
  r.add<Limiter>("Limiter", "clamp to [min, max] with an optional slew-rate limit");
  r.add<MovingAverage>("MovingAverage", "mean of the last `window` samples, O(1) per cycle");
  r.add<SineSource>("SineSource", "sine test signal, phase exact from the cycle count");
  r.add<Integrator>("Integrator", "integrator with clamping anti-windup and reset");
}

}  // namespace edm::blocks
