#pragma once
// The function-block interface (IEC 61131-3 FB, ros2_control-style lifecycle).
//
//   non-RT  visit_params() (loader fills Params) → validate() → configure() → activate()
//   RT      update() every cycle of the owning task; params_changed() after a runtime write;
//           enter_safe_state() on entry into FAULT/ESTOP
//
// A block type derives from BlockWithParams<Params> (or Block for parameterless blocks),
// declares its pins in visit_pins() and is registered by name in register_builtin_blocks().

#include <cstdint>
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
};

class Block : public SafeStateHandler {
 public:
  Block() = default;
  ~Block() override = default;
  Block(const Block&) = delete;
  Block& operator=(const Block&) = delete;

  /// Names every pin. Called at load time (non-RT) and by listings.
  virtual void visit_pins(PinVisitor& v) = 0;
  /// Names every parameter of the live parameter set. Non-RT, load time only.
  virtual void visit_params(ParamVisitor& /*v*/) {}
  /// Checks the live parameters after the loader filled them. Non-RT.
  [[nodiscard]] virtual std::vector<ParamError> validate() const { return {}; }
  /// Prepares for running on a task (precompute, allocate). Non-RT. Returns problems, if any.
  virtual std::vector<ParamError> configure(const BlockSetup& /*setup*/) { return {}; }
  /// Resets internal state before the first cycle. Non-RT.
  virtual void activate() noexcept {}
  /// One scan. RT-safe: must not allocate, lock, log synchronously or throw.
  virtual BlockStatus update(const CycleContext& ctx) noexcept = 0;
  /// Default safe state: nothing to do. RT-safe.
  void enter_safe_state(const SafeStateRequest& /*request*/) noexcept override {}

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
};

/// Base for blocks with a Params struct: live parameters (read by update()) and a shadow copy
/// (non-RT) on which runtime writes are validated before being queued to the RT thread.
/// Base is Block, or another Block-derived interface such as IoDriver.
template <class P, class Base = Block>
class BlockWithParams : public Base {
 public:
  using Params = P;

  void visit_params(ParamVisitor& v) override { params_.visit(v); }
  [[nodiscard]] std::vector<ParamError> validate() const override { return params_.validate(); }
  [[nodiscard]] std::size_t param_count() override { return field_refs(shadow_).size(); }
  std::vector<ParamError> stage_param(std::size_t index, const ParamValue& v) override {
    P candidate = shadow_;
    auto refs = field_refs(candidate);
    if (index >= refs.size() || !write_param(refs[index], v)) {
      return {{"", "parameter type mismatch or not writable at run time"}};
    }
    auto errs = candidate.validate();
    if (errs.empty()) {
      shadow_ = candidate;
    }
    return errs;
  }
  void apply_param(std::size_t index, const ParamValue& v) noexcept override {
    IndexWriter w{index, v};
    params_.visit(w);
    params_changed();
  }
  [[nodiscard]] ParamValue read_param(std::size_t index) const override {
    P copy = shadow_;
    auto refs = field_refs(copy);
    return index < refs.size() ? edm::rt::read_param(refs[index]) : ParamValue{};
  }
  void commit_params() override { shadow_ = params_; }

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
  // Writes one field chosen by index; allocation-free so it can run on the RT thread.
  class IndexWriter final : public ParamVisitor {
   public:
    IndexWriter(std::size_t index, const ParamValue& v) : index_(index), value_(v) {}

   protected:
    void on_param(std::string_view, ParamRef ref, ParamInfo) override {
      if (n_++ == index_) {
        write_param(ref, value_);
      }
    }

   private:
    std::size_t index_;
    ParamValue value_;
    std::size_t n_{0};
  };
  static std::vector<ParamRef> field_refs(P& p) {
    struct Collect final : ParamVisitor {
      std::vector<ParamRef> refs;
      void on_param(std::string_view, ParamRef ref, ParamInfo) override { refs.push_back(ref); }
    } c;
    p.visit(c);
    return c.refs;
  }

  P shadow_{};
};

}  // namespace edm::rt
