#pragma once
// SineSource: a test-signal generator, out = offset + amplitude·sin(2π·f·t + phase) with
// t = cycle·dt (cycle from the CycleContext, dt the task period given to configure()).
//
// The phase is computed afresh from the cycle count every cycle, so there is no accumulating
// phase error: c = f·dt (sine periods per sample) is held as a double-double (error-free
// products from the integer period in ns), n·c is reduced modulo 1 with an exact product, and
// only the fraction in [0, 1) is turned into an angle. The phase stays accurate to ~1e-15 rad
// at any cycle count below 2^53 (over 285 000 years at 1 kHz).
//
// Frequencies at or above the Nyquist rate 1/(2·dt) alias (sampling, not a bug). The cycle count
// counts executed cycles: a slot omitted after an overrun delays the sine by one period dt.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct SineSourceParams {
  double amplitude{1.0};     // [signal unit]
  double frequency_hz{1.0};  // [Hz], > 0
  double phase_rad{0.0};     // [rad] at cycle 0
  double offset{0.0};        // [signal unit]

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): signals within ±1e12 (param_ranges.hpp); up to 100 kHz, ten times the
    // Nyquist frequency of the fastest (10 kHz) task; a phase within ±1000 rad.
    v.param("amplitude", amplitude, {"", "peak amplitude, in the signal's unit", ranges::kSignal});
    v.param("frequency_hz", frequency_hz, {"Hz", "frequency", rt::open_closed(0.0, 1.0e5)});
    v.param("phase_rad", phase_rad, {"rad", "phase at cycle 0", rt::closed(-1000.0, 1000.0)});
    v.param("offset", offset, {"", "added to the sine, in the signal's unit", ranges::kSignal});
  }
};

class SineSource final : public rt::BlockWithParams<SineSourceParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override;
  /// Non-RT. Needs a task period > 0.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// RT-safe. Always kOk.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  /// The output for a given cycle number, without touching the pin. RT-safe.
  [[nodiscard]] double value_at(std::uint64_t cycle) const noexcept;

 protected:
  void params_changed() noexcept override;

 private:
  void compute_step() noexcept;

  rt::Output<double> out_;
  rt::Duration period_{};
  double step_hi_{0.0};  // f·dt [periods per sample] = step_hi_ + step_lo_
  double step_lo_{0.0};
};

}  // namespace edm::blocks
