#pragma once
// The `hal` I/O driver (docs/hal.md): edmplc as a LinuxCNC HAL userspace component.
//
//   HAL side (servo thread, hm2 / parport / edm-sim-hal)   edmplc's I/O task (RT)
//   pins in HAL shared memory  ◀──── net ────▶   read_inputs(): every input pin's value, scaled,
//                                                 into io.<name>; counters as their change;
//                                                 the heartbeat's age → alarm 121 when stale
//                                                 write_outputs(): io.<name> (or the safe value in
//                                                 FAULT/ESTOP) scaled into the output pins
//
// The cycle reads and writes HAL's shared memory directly: volatile loads and stores through the
// pin's slot (component.hpp), no lock, no system call, no allocation, no log. The two sides run on
// separate clocks; free-running counters (pulses by class, Td sum and count) make that harmless:
// a cycle takes what the HAL side added since the last one, none is lost or counted twice.
//
// The HAL component is made at build time, in configure(), when the driver is registered to
// attach (edmplc running); `--check`, `--list-vars` and the tests' offline builds register it
// detached: the same pins, backed by the driver's own memory (set_raw() writes an input as the
// HAL side would). Missing HAL, a component name in use, a pin or link HAL refuses: configure()
// errors (the loader reports them at the config's file:line:col; edmplc exits 2).
//
// Stale HAL side: an input with `role: heartbeat` must change at least every `stale_cycles`
// cycles of the I/O task; otherwise alarm 121 io_stale (FAULT: the safe state) is raised every
// cycle while it lasts, so the safe state comes `stale_cycles + 1` cycles after the last beat.
// An output with `role: heartbeat_out` counts edmplc's cycles for the HAL side's own watchdog.
//
// Pacing (`pace_wait` > 0): read_inputs() first spins (no system call, no lock) until the
// heartbeat changes from its value at the cycle's release, or pace_wait has passed, so the inputs
// are latched just after the HAL side's next step instead of up to a period later; it costs the
// CPU time of the wait, every cycle (docs/hal.md "Pacing edmplc").
//
// Thread-safety: the RT methods from the I/O task's thread; configure/start/stop from the
// controlling thread.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "edm/hal/component.hpp"
#include "edm/hal/pin_map.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/type_registry.hpp"

namespace edm::hal {

struct HalDriverParams {
  std::string component{"edmplc"};
  std::int64_t stale_cycles{20};
  rt::Duration start_timeout{std::chrono::seconds(5)};
  rt::Duration pace_wait{0};  // > 0: each cycle waits up to this long for the next heartbeat
  std::string online_pin;     // a BOOL output pin, true while the heartbeat is fresh; "" = none

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class HalDriver : public rt::BlockWithParams<HalDriverParams, rt::IoDriver> {
 public:
  explicit HalDriver(bool attach = false);
  ~HalDriver() override;

  [[nodiscard]] bool has_pin_map() const noexcept override { return true; }
  std::vector<rt::PinMapError> set_pin_map(const std::vector<rt::PinMapEntry>& entries) override;
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  void visit_pins(rt::PinVisitor& v) override;
  void activate() noexcept override;

  void read_inputs(const rt::CycleContext& ctx) noexcept override;
  void write_outputs(const rt::CycleContext& ctx) noexcept override;
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;
  /// Waits (bounded by start_timeout) for the heartbeat's first change. Non-RT.
  void start() override;
  /// Writes the safe values once more. Non-RT.
  void stop() noexcept override;
  /// The HAL side beats in wall time.
  [[nodiscard]] bool wall_time_io() const noexcept override { return true; }

  [[nodiscard]] const std::vector<HalPin>& pin_map() const noexcept { return map_; }
  /// Detached only (tests): sets pin i's raw value as the HAL side would. Not RT.
  void set_raw(std::size_t i, double raw) noexcept { pin_write(slots_[i], raw); }
  /// Pin i's raw value. RT-safe.
  [[nodiscard]] double raw(std::size_t i) const noexcept { return pin_read(slots_[i]); }
  [[nodiscard]] bool attached() const noexcept { return component_.is_open(); }
  /// Cycles whose pacing wait ended on a beat (not on pace_wait). I/O task's thread.
  [[nodiscard]] std::uint64_t paced_cycles() const noexcept { return paced_; }

 private:
  struct Local {  // a detached pin's storage: the slot points at the value
    void* addr{nullptr};
    alignas(8) std::uint64_t value{0};
  };

  void write_safe(bool estop) noexcept;
  [[nodiscard]] std::vector<rt::ParamError> attach();

  bool attach_{false};
  std::vector<HalPin> map_;
  std::vector<PinSlot> slots_;  // per map_ entry
  std::unique_ptr<Local[]> local_;
  Component component_;
  // The io pins, by kind; kind_slot_[i] indexes the vector of map_[i]'s kind.
  std::vector<std::unique_ptr<rt::Output<bool>>> bool_in_;
  std::vector<std::unique_ptr<rt::Output<double>>> real_in_;
  std::vector<std::unique_ptr<rt::Output<std::int64_t>>> int_in_;
  std::vector<std::unique_ptr<rt::Input<bool>>> bool_out_;
  std::vector<std::unique_ptr<rt::Input<double>>> real_out_;
  std::vector<std::unique_ptr<rt::Input<std::int64_t>>> int_out_;
  std::vector<std::size_t> kind_slot_;
  rt::Output<bool> online_;

  // RT side
  rt::Machine* machine_{nullptr};
  std::vector<std::uint32_t> last_count_;  // counters: the raw value of the last cycle
  bool counted_{false};
  std::size_t heartbeat_{SIZE_MAX};  // map_ index, SIZE_MAX = none
  std::size_t heartbeat_out_{SIZE_MAX};
  std::uint32_t beat_seen_{0};
  std::uint32_t beat_out_{0};
  bool beat_valid_{false};
  std::uint64_t age_{0};
  std::uint64_t paced_{0};   // cycles whose wait saw the beat (pacing), for the statistics
  std::uint64_t cycles_{0};  // read_inputs() calls
  bool stale_{false};
  std::string stale_source_;  // "io.hal(<component>)": alarm sources live as long as this
};

/// Registers "hal". `attach`: edmplc about to run (the component is made in configure());
/// false: `--check`, listings and offline tools (the pins are the driver's own memory). Non-RT.
void register_hal_driver(rt::DriverRegistry& r, bool attach);

}  // namespace edm::hal
