#pragma once
// The function-block interface (IEC 61131-3 FB, ros2_control-style lifecycle).
//
//   non-RT  visit_params() (loader fills Params) → validate() → configure() → (YAML wiring)
//           → bind() → activate()
//   RT      update() every cycle of the owning task; params_changed() after a runtime write;
//           enter_safe_state() on entry into FAULT/ESTOP
//
// A block type derives from BlockWithParams<Params> (or Block for parameterless blocks),
// declares its pins as members named in its pin table (pins_), and is registered by name in
// register_builtin_blocks().
// Pins are public Input<T>/Output<T> members, so a C++ PROGRAM connects its children by member.

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/machine.hpp"
#include "edm/runtime/param.hpp"
#include "edm/runtime/pin.hpp"
#include "edm/runtime/time.hpp"

namespace edm::machining {
struct MachineTables;
}

namespace edm::rt {

class Clock;
class JobStore;
class ManualControl;
class Electrode;

enum class BlockStatus : std::int8_t { kOk = 0, kSaturated = 1, kFault = -1 };

/// The more severe of two statuses (fault > saturated > ok). RT-safe.
constexpr BlockStatus worst(BlockStatus a, BlockStatus b) noexcept {
  if (a == BlockStatus::kFault || b == BlockStatus::kFault) {
    return BlockStatus::kFault;
  }
  if (a == BlockStatus::kSaturated || b == BlockStatus::kSaturated) {
    return BlockStatus::kSaturated;
  }
  return BlockStatus::kOk;
}

/// Why a block reported kFault, for its alarm (issue 33: "alarms that say why"). `text` is a
/// static string in words ("no spark for the timeout while orbiting"); `value` the quantity that
/// tripped it (NaN: none). RT-safe to copy.
struct FaultCause {
  const char* text{nullptr};
  double value{std::numeric_limits<double>::quiet_NaN()};
};

/// What a block sees each cycle. RT-safe to read.
struct CycleContext {
  TimePoint release{};     // scheduled release time of this cycle (on the task's grid)
  Duration period{};       // the task interval
  double dt_s{0.0};        // the task interval in seconds
  std::uint64_t cycle{0};  // cycle number of the task, from 0
  MachineState state{MachineState::kReady};
  const Clock* clock{nullptr};
};

/// What configure() is told. Non-RT.
/// What configure() is given. The pointers are the runtime's (they outlive every block); they
/// are null when a block is built outside a Runtime (unit tests), so blocks that need them must
/// report a configure error rather than dereference null.
struct BlockSetup {
  std::string_view instance;  // "program.block"
  Duration period{};          // interval of the task the block runs on
  Machine* machine{nullptr};  // the state machine (commands from a sequencer; alarms)
  JobStore* job{nullptr};     // the loaded part program (job sequencers)
  const machining::MachineTables* tables{nullptr};  // conditions and soft limits of the config
  ManualControl* manual{nullptr};  // the operator's manual motion requests (job sequencers)
  Electrode* electrode{nullptr};   // the electrode length estimate (job sequencers)
};

class Block : public SafeStateHandler {
 public:
  Block() = default;
  ~Block() override = default;
  Block(const Block&) = delete;
  Block& operator=(const Block&) = delete;

  /// Names every pin. Called at load time (non-RT) and by listings. By default the pins
  /// declared with this block's table (`rt::Input<double> x_mm{pins_, "x_mm", "mm"};`).
  virtual void visit_pins(PinVisitor& v) { pins_.visit(v); }
  /// Names every parameter of the live parameter set. Non-RT, load time only.
  virtual void visit_params(ParamVisitor& /*v*/) {}
  /// Checks the live parameters after the loader filled them. Non-RT.
  [[nodiscard]] virtual std::vector<ParamError> validate() const { return {}; }
  /// Prepares for running on a task (precompute, allocate). Non-RT. Returns problems, if any.
  virtual std::vector<ParamError> configure(const BlockSetup& /*setup*/) { return {}; }
  /// Called once the YAML wiring is resolved, before activate(): a composite connects its
  /// children here, seeing its own final inputs. Non-RT.
  virtual void bind() {}
  /// Resets internal state before the first cycle. Non-RT.
  virtual void activate() noexcept {}
  /// One scan. RT-safe: must not allocate, lock, log synchronously or throw.
  virtual BlockStatus update(const CycleContext& ctx) noexcept = 0;
  /// Default safe state: nothing to do. RT-safe.
  void enter_safe_state(const SafeStateRequest& /*request*/) noexcept override {}
  /// After update() returned kFault: the full name of the block that raised it when that is a
  /// child ("cnc.job.drill.gap"), or nullptr for the block itself. RT-safe; the string lives as
  /// long as the block.
  [[nodiscard]] virtual const char* fault_source() const noexcept { return nullptr; }
  /// After update() returned kFault: why, as the block (or its faulting child) said it with
  /// fault(); text nullptr when it gave no cause. RT-safe.
  [[nodiscard]] virtual FaultCause fault_cause() const noexcept { return fault_cause_; }

  // Runtime parameter access (variable registry). Blocks get these from BlockWithParams.
  /// Number of parameter fields.
  [[nodiscard]] virtual std::size_t param_count() { return 0; }
  /// Validates a write of field `index` on the shadow copy and keeps it there if valid. Non-RT.
  virtual std::vector<ParamError> stage_param(std::size_t index, const ParamValue& v);
  /// Applies a staged write to the live parameters. RT (start of the owning task's cycle).
  virtual void apply_param(std::size_t index, const ParamValue& v) noexcept;
  /// Reads field `index` from the shadow copy (what the block has or will have next cycle).
  /// Non-RT.
  [[nodiscard]] virtual ParamValue read_param(std::size_t index) const;
  /// Copies the live parameters to the shadow copy once loading is done. Non-RT.
  virtual void commit_params() {}

 protected:
  /// Records why and returns kFault: `return fault("a non-finite input", x);`. `text` must be a
  /// static string. RT-safe.
  BlockStatus fault(const char* text,
                    double value = std::numeric_limits<double>::quiet_NaN()) noexcept {
    fault_cause_ = {text, value};
    return BlockStatus::kFault;
  }

  /// This block's named pins, in declaration order; declared before any derived member.
  PinTable pins_;

 private:
  FaultCause fault_cause_{};
};

/// Base for blocks with a Params struct: live parameters (read by update()) and a shadow copy
/// (non-RT) on which runtime writes are validated before being queued to the RT thread.
/// Base is Block, or another Block-derived interface such as IoDriver or CompositeBlock; the
/// Base's own parameters (a composite's children's) follow this block's in index order.
template <class P, class Base = Block>
class BlockWithParams : public Base {
 public:
  using Params = P;

  void visit_params(ParamVisitor& v) override {
    params_.visit(v);
    Base::visit_params(v);
  }
  [[nodiscard]] std::vector<ParamError> validate() const override {
    std::vector<ParamError> errs = validate_params(params_);
    for (ParamError& e : Base::validate()) {
      errs.push_back(std::move(e));
    }
    return errs;
  }
  /// RT-safe (counts without allocating).
  [[nodiscard]] std::size_t param_count() override { return own_count() + Base::param_count(); }
  std::vector<ParamError> stage_param(std::size_t index, const ParamValue& v) override {
    if (index >= own_count()) {
      return Base::stage_param(index - own_count(), v);
    }
    P candidate = shadow_;
    ParamAt at(index);
    candidate.visit(at);
    if (at.spec.load_time_only) {
      return {{"", "load time only (set it in the config)"}};
    }
    if (!write_param(at.ref, v)) {
      return {{"", "parameter type mismatch or not writable at run time"}};
    }
    auto errs = validate_params(candidate);
    if (errs.empty()) {
      shadow_ = candidate;
    }
    return errs;
  }
  void apply_param(std::size_t index, const ParamValue& v) noexcept override {
    if (index >= own_count()) {
      Base::apply_param(index - own_count(), v);
      return;
    }
    ParamAt at(index);
    params_.visit(at);
    write_param(at.ref, v);
    params_changed();
  }
  [[nodiscard]] ParamValue read_param(std::size_t index) const override {
    if (index >= own_count()) {
      return Base::read_param(index - own_count());
    }
    P copy = shadow_;
    ParamAt at(index);
    copy.visit(at);
    return at.found ? edm::rt::read_param(at.ref) : ParamValue{};
  }
  void commit_params() override {
    shadow_ = params_;
    Base::commit_params();
  }

  [[nodiscard]] const P& params() const noexcept { return params_; }
  /// Sets the live parameters directly (tests and C++ programs, before activate()). Non-RT.
  void set_params(const P& p) {
    params_ = p;
    shadow_ = p;
  }

 protected:
  /// Called on the RT thread after a runtime parameter write (recompute coefficients). RT-safe.
  virtual void params_changed() noexcept {}

  P params_{};

 private:
  [[nodiscard]] std::size_t own_count() const noexcept {
    static const std::size_t n = [] {
      P p{};
      ParamCounter c;
      p.visit(c);
      return c.count;
    }();
    return n;
  }

  P shadow_{};
};

}  // namespace edm::rt
