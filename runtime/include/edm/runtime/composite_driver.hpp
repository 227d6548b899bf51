#pragma once
// The composite I/O driver (`machine.io.driver: composite`): several drivers as one process
// image, e.g. the simulator's gap and axes beside a Modbus TCP remote I/O's door switch,
// E-stop and flushing pump (config/machines/drill-modbus-sim.yaml). The runtime builder creates,
// configures and adds the children (each from its own `drivers[i]` entry, so a problem is
// reported at its own file:line:col); the composite then forwards every call to each child in
// list order.
//
//  - pins: every child's, unprefixed, in one io. namespace (`io.z_mm`, `io.door_closed`); a
//    name two children declare is a config error;
//  - parameters: io.<param>, or io.<name>.<param> for a child given a `name` (two drivers of
//    one type need names); a parameter name two children declare is a config error;
//  - fault(): the first child's fault in list order; set_seed(): every child that takes one;
//  - read_inputs(), write_outputs(), enter_safe_state(), start(), stop(): every child in order.
//
// RT-safety: read_inputs/write_outputs/enter_safe_state/fault/apply_param are as RT-safe as the
// children's (no allocation of their own); the rest is non-RT. Thread-safety: as IoDriver.

#include <memory>
#include <string>
#include <vector>

#include "edm/runtime/child_params.hpp"
#include "edm/runtime/io_driver.hpp"

namespace edm::rt {

class CompositeDriver final : public IoDriver {
 public:
  /// Adds a configured child. Non-RT, build time (before bind()).
  void add(std::string name, std::unique_ptr<IoDriver> driver);
  [[nodiscard]] std::size_t size() const noexcept { return children_.size(); }
  [[nodiscard]] IoDriver& child(std::size_t i) noexcept { return *children_[i]; }

  void visit_pins(PinVisitor& v) override;
  void visit_params(ParamVisitor& v) override;
  [[nodiscard]] std::vector<ParamError> validate() const override;
  [[nodiscard]] std::size_t param_count() override;
  std::vector<ParamError> stage_param(std::size_t index, const ParamValue& v) override;
  void apply_param(std::size_t index, const ParamValue& v) noexcept override;
  [[nodiscard]] ParamValue read_param(std::size_t index) const override;
  void commit_params() override;
  void bind() override;
  void activate() noexcept override;

  void read_inputs(const CycleContext& ctx) noexcept override;
  void write_outputs(const CycleContext& ctx) noexcept override;
  void enter_safe_state(const SafeStateRequest& request) noexcept override;
  [[nodiscard]] IoFault fault() const noexcept override;
  bool set_seed(std::uint64_t seed) override;
  void start() override;
  void stop() noexcept override;
  /// True when any of its drivers is.
  [[nodiscard]] bool wall_time_io() const noexcept override;

 private:
  std::vector<std::unique_ptr<IoDriver>> children_;
  ChildParams params_;  // io.<param>, or io.<name>.<param> for a named child
};

}  // namespace edm::rt
