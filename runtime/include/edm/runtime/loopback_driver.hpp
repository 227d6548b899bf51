#pragma once
// The loopback I/O driver: what the programs write to io.ao<k> / io.do<k> at the end of a cycle
// is what they read from io.ai<k> / io.di<k> at the start of the next one (like wiring a real
// output card back to an input card). In FAULT/ESTOP it publishes the safe values 0 / false
// whatever the programs write. For tests and benchmarks; the simulator is the default driver
// of the machine configs.
// Thread-safety: owned by the I/O task's thread; inject_fault() may be called from any thread.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/type_registry.hpp"

namespace edm::rt {

struct LoopbackParams {
  std::int64_t channels{4};  // analog and digital channel pairs

  void visit(ParamVisitor& v) {
    v.param("channels", channels, {"", "analog and digital channel pairs", closed(1, 64)});
  }
};

class LoopbackDriver final : public BlockWithParams<LoopbackParams, IoDriver> {
 public:
  std::vector<ParamError> configure(const BlockSetup& setup) override;
  void visit_pins(PinVisitor& v) override;
  void read_inputs(const CycleContext& ctx) noexcept override;
  void write_outputs(const CycleContext& ctx) noexcept override;
  void enter_safe_state(const SafeStateRequest& request) noexcept override;
  [[nodiscard]] IoFault fault() const noexcept override;

  /// Test hook: report a driver fault (code != 0) from the next cycle on; 0 clears it.
  void inject_fault(int code) noexcept { fault_code_.store(code); }
  /// How many times enter_safe_state() was called.
  [[nodiscard]] int safe_state_entries() const noexcept { return safe_entries_.load(); }

 private:
  struct Channel {
    std::string ai, ao, di, dout;
    Output<double> ai_pin;
    Input<double> ao_pin;
    Output<bool> di_pin;
    Input<bool> do_pin;
    double ao_latched{0.0};
    bool do_latched{false};
  };
  std::vector<std::unique_ptr<Channel>> channels_;
  std::atomic<int> fault_code_{0};
  std::atomic<int> safe_entries_{0};
};

/// Registers the drivers that live in the runtime ("loopback").
void register_runtime_drivers(DriverRegistry& r);

}  // namespace edm::rt
