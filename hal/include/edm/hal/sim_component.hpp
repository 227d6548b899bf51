#pragma once
// edm-sim-hal's core (docs/hal.md "edm-sim-hal"): the EDM plant simulator (sim/) as a HAL
// userspace component, with the pins a real machine's hardware would have:
//   from the pulse analyser (HAL_OUT, free-running u32 counters that wrap): n-open, n-normal,
//     n-transient-arc, n-stable-arc, n-short, td-sum-ns, td-count; per step: ratio-open …
//     ratio-short, gap-voltage (mean, V), short (the newest pulse was a short), hist-open,
//     hist-short, hist-arc (the last 32 pulses, bit 0 newest), rab;
//   from the axes: x-pos-fb, y-pos-fb, z-pos-fb (mm), ref-x/-y/-z, contact (touch sensing),
//     drive-fault; heartbeat (u32, +1 per step);
//   to the generator and the axes (HAL_IN): x-vel-cmd, y-vel-cmd, z-vel-cmd (mm/s, +z away from
//     the work), gen-arm, gen-on, polarity-positive, on-time-us, off-time-us, arc-off-time-us,
//     servo-ref-v, flushing-on, flushing-strength, rotation-on, touch-mode, pos-set-x/-y/-z with
//     pos-value-x/-y/-z (mm); plc-heartbeat (edmplc's heartbeat_out);
//   what only a simulator knows (HAL_OUT, for the SIL test and its job report): truth.depth-mm,
//     truth.wall-radius-mm, truth.electrode-mm, truth.hole-work-x-mm, truth.hole-work-y-mm.
// step() runs the plant to the wall time given and is called by the component's own paced loop
// (edm_sim_hal.cpp): a userspace component cannot export a function to a HAL thread in uspace.
// When plc-heartbeat has beaten once and then stops for plc_timeout, the simulated generator and
// drives fall safe by themselves (generator off, axes stopped), as a real generator's watchdog.
//
// Thread-safety: one thread. step() is RT-safe (no allocation, no lock).

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "edm/hal/component.hpp"
#include "edm/sim/params.hpp"
#include "edm/sim/plant.hpp"

namespace edm::hal {

struct SimComponentOptions {
  std::string name{"edm-sim"};
  std::string preset{"drill"};
  std::uint64_t seed{1};
  bool wall_sparks{true};
  std::chrono::nanoseconds plc_timeout{std::chrono::milliseconds(50)};
};

class SimComponent {
 public:
  /// Builds the plant and the component; "" in `error` on success. Non-RT.
  explicit SimComponent(const SimComponentOptions& o, std::string& error);
  ~SimComponent();
  SimComponent(const SimComponent&) = delete;
  SimComponent& operator=(const SimComponent&) = delete;

  /// Reads the commands, runs the plant to `t` (plant time, from 0), publishes. RT-safe.
  void step(std::chrono::nanoseconds t) noexcept;
  [[nodiscard]] std::uint64_t steps() const noexcept { return steps_; }
  [[nodiscard]] bool plc_lost() const noexcept { return plc_lost_; }

 private:
  struct Pins;
  SimComponentOptions opt_;
  Component comp_;
  std::unique_ptr<sim::Plant> plant_;
  std::unique_ptr<Pins> pins_;
  std::uint32_t counters_[7]{};  // n by class (5), td sum, td count
  std::uint64_t steps_{0};
  std::uint32_t plc_beat_{0};
  bool plc_seen_{false};
  bool plc_lost_{false};
  std::chrono::nanoseconds plc_last_{0};
  bool pos_set_before_[3]{};
};

}  // namespace edm::hal
