#pragma once
// Blocks used only by tests: they record what the scheduler did and inject execution time.

#include <time.h>

#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/composite_block.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/type_registry.hpp"

namespace edm::test {

/// One entry per update(): which block, its release and the clock's time when it ran.
struct RunRecord {
  const char* who;
  rt::TimePoint release;
  rt::TimePoint started;
  std::uint64_t cycle;
  rt::MachineState state;
};

/// Shared log of RunRecords (reserved up front so recording never allocates).
inline std::vector<RunRecord>& run_log() {
  static std::vector<RunRecord> log;
  return log;
}

/// Records each update into run_log(); `tag` names it.
struct RecorderParams {
  std::string tag{"rec"};
  void visit(rt::ParamVisitor& v) { v.param("tag", tag); }
  [[nodiscard]] std::vector<rt::ParamError> validate() const { return {}; }
};
class Recorder final : public rt::BlockWithParams<RecorderParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override { v.output("count", count_); }
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override {
    auto& log = run_log();
    if (log.size() < log.capacity()) {
      log.push_back({params_.tag.c_str(), ctx.release, ctx.clock->now(), ctx.cycle, ctx.state});
    }
    count_.set(count_.get() + 1);
    return rt::BlockStatus::kOk;
  }
  int safe_entries{0};
  void enter_safe_state(const rt::SafeStateRequest&) noexcept override { ++safe_entries; }

 private:
  rt::Output<std::int64_t> count_;
};

/// Charges execution time to the virtual clock: cost_us on cycles [from_cycle, from_cycle +
/// cycles) (cycles < 0: forever). Lets tests inject overruns deterministically.
struct CostParams {
  double cost_us{0.0};
  std::int64_t from_cycle{0};
  std::int64_t cycles{-1};
  void visit(rt::ParamVisitor& v) {
    v.param("cost_us", cost_us, "us");
    v.param("from_cycle", from_cycle);
    v.param("cycles", cycles);
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const { return {}; }
};
class Cost final : public rt::BlockWithParams<CostParams> {
 public:
  void visit_pins(rt::PinVisitor& /*v*/) override {}
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override {
    const auto c = static_cast<std::int64_t>(ctx.cycle);
    const bool active =
        c >= params_.from_cycle && (params_.cycles < 0 || c < params_.from_cycle + params_.cycles);
    if (active && ctx.clock != nullptr && ctx.clock->kind() == rt::ClockKind::kVirtual) {
      auto* vc = const_cast<rt::VirtualClock*>(static_cast<const rt::VirtualClock*>(ctx.clock));
      vc->advance(rt::Duration{static_cast<std::int64_t>(params_.cost_us * 1000.0)});
    }
    return rt::BlockStatus::kOk;
  }
};

/// Cycles [from_cycle, from_cycle + cycles) of a block's task (cycles < 0: forever).
struct InjectWindow {
  std::int64_t from_cycle{0};
  std::int64_t cycles{-1};
  void visit(rt::ParamVisitor& v) {
    v.param("from_cycle", from_cycle);
    v.param("cycles", cycles);
  }
  [[nodiscard]] bool active(std::uint64_t cycle) const {
    const auto c = static_cast<std::int64_t>(cycle);
    return c >= from_cycle && (cycles < 0 || c < from_cycle + cycles);
  }
};

/// A host stall of stall_us inside the cycle on the active cycles: the virtual clock's time moves
/// without CPU time (VirtualClock::stall); on the real clock the thread sleeps (wall time passes,
/// its CPU time does not: what the runtime sees when the host deschedules the process).
struct HostStallParams {
  double stall_us{0.0};
  InjectWindow window;
  void visit(rt::ParamVisitor& v) {
    v.param("stall_us", stall_us, "us");
    window.visit(v);
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const { return {}; }
};
class HostStall final : public rt::BlockWithParams<HostStallParams> {
 public:
  void visit_pins(rt::PinVisitor& /*v*/) override {}
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override {
    if (!params_.window.active(ctx.cycle) || ctx.clock == nullptr) {
      return rt::BlockStatus::kOk;
    }
    const rt::Duration d{static_cast<std::int64_t>(params_.stall_us * 1000.0)};
    if (ctx.clock->kind() == rt::ClockKind::kVirtual) {
      const_cast<rt::VirtualClock*>(static_cast<const rt::VirtualClock*>(ctx.clock))->stall(d);
    } else {
      timespec ts{static_cast<time_t>(d.count() / 1'000'000'000),
                  static_cast<long>(d.count() % 1'000'000'000)};
      while (nanosleep(&ts, &ts) != 0) {
      }
    }
    return rt::BlockStatus::kOk;
  }
};

/// Burns burn_us of the thread's own CPU time on the active cycles (a block that really takes
/// that long): virtual clock, charged with VirtualClock::advance; real clock, a busy loop until
/// the thread's CPU clock has moved by burn_us (however much the host preempts it meanwhile).
struct CpuBurnParams {
  double burn_us{0.0};
  InjectWindow window;
  void visit(rt::ParamVisitor& v) {
    v.param("burn_us", burn_us, "us");
    window.visit(v);
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const { return {}; }
};
class CpuBurn final : public rt::BlockWithParams<CpuBurnParams> {
 public:
  void visit_pins(rt::PinVisitor& /*v*/) override {}
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override {
    if (!params_.window.active(ctx.cycle) || ctx.clock == nullptr) {
      return rt::BlockStatus::kOk;
    }
    const rt::Duration d{static_cast<std::int64_t>(params_.burn_us * 1000.0)};
    if (ctx.clock->kind() == rt::ClockKind::kVirtual) {
      const_cast<rt::VirtualClock*>(static_cast<const rt::VirtualClock*>(ctx.clock))->advance(d);
    } else {
      const rt::Duration until = ctx.clock->thread_cpu_time() + d;
      while (ctx.clock->thread_cpu_time() < until) {
      }
    }
    return rt::BlockStatus::kOk;
  }
};

/// out = in + 1 each cycle (REAL), and an LINT cycle counter; flags a fault when in is NaN.
class AddOne final : public rt::Block {
 public:
  void visit_pins(rt::PinVisitor& v) override {
    v.input("in", in);
    v.output("out", out);
    v.input("flag", flag);
    v.output("ticks", ticks);
  }
  rt::BlockStatus update(const rt::CycleContext&) noexcept override {
    const double x = in.get();
    ticks.set(ticks.get() + 1);
    if (x != x) {
      return rt::BlockStatus::kFault;
    }
    out.set(x + 1.0);
    return rt::BlockStatus::kOk;
  }

  rt::Input<double> in;
  rt::Output<double> out;
  rt::Input<bool> flag;
  rt::Output<std::int64_t> ticks;
};

/// A block with every parameter type, for parameter reading/writing tests.
struct AllParams {
  double gain{1.0};
  std::int64_t count{3};
  bool enabled{true};
  rt::Duration hold{std::chrono::milliseconds(5)};
  std::string label{"x"};
  void visit(rt::ParamVisitor& v) {
    v.param("gain", gain, "1", "must be in [0, 100]");
    v.param("count", count);
    v.param("enabled", enabled);
    v.param("hold", hold, "s");
    v.param("label", label);
  }
  [[nodiscard]] std::vector<rt::ParamError> validate() const {
    std::vector<rt::ParamError> errs;
    rt::require_range(errs, "gain", gain, 0.0, 100.0);
    if (count < 1) {
      errs.push_back({"count", "must be >= 1"});
    }
    return errs;
  }
};
class ParamProbe final : public rt::BlockWithParams<AllParams> {
 public:
  void visit_pins(rt::PinVisitor& v) override { v.output("gain_seen", gain_seen_); }
  rt::BlockStatus update(const rt::CycleContext&) noexcept override {
    gain_seen_.set(params_.gain);
    return rt::BlockStatus::kOk;
  }
  int changes{0};

 protected:
  void params_changed() noexcept override { ++changes; }

 private:
  rt::Output<double> gain_seen_;
};

/// A C++ PROGRAM type: a two-step sequencer over two child blocks. Step 0 runs `fill` (AddOne
/// fed back on itself) until its output reaches `target`, then step 1 runs `drain` once per cycle.
/// `step` (LINT) is its own output; the safe state parks it in step 0.
struct TwoStepParams {
  double target{3.0};
  void visit(rt::ParamVisitor& v) { v.param("target", target, {.range = rt::kPositive}); }
};
class TwoStep final : public rt::BlockWithParams<TwoStepParams, rt::CompositeBlock> {
 public:
  TwoStep() : fill_(add_child<AddOne>("fill")), drain_(add_child<Recorder>("drain")) {}
  int safe_entries{0};

 protected:
  rt::BlockStatus update_self(const rt::CycleContext& ctx) noexcept override {
    if (rt::is_safe_state(ctx.state)) {
      return rt::BlockStatus::kOk;  // parked until reset
    }
    rt::BlockStatus s = rt::BlockStatus::kOk;
    if (step_.get() == 0) {
      s = step(fill_, ctx);
      if (fill_.out.get() >= params_.target) {
        step_.set(1);
      }
    } else {
      s = step(drain_, ctx);
    }
    return s;
  }
  void visit_own_pins(rt::PinVisitor& v) override { v.output("step", step_); }
  void bind_self() override { fill_.in.connect(fill_.out); }  // the child fed back on itself
  void activate_self() noexcept override { step_.set(0); }
  void safe_state_self(const rt::SafeStateRequest&) noexcept override {
    ++safe_entries;
    step_.set(0);
  }

 private:
  AddOne& fill_;
  Recorder& drain_;
  rt::Output<std::int64_t> step_;
};

inline void register_test_blocks(rt::BlockRegistry& r) {
  r.add<TwoStep>("TwoStep");
  r.add<Recorder>("Recorder");
  r.add<Cost>("Cost");
  r.add<HostStall>("HostStall");
  r.add<CpuBurn>("CpuBurn");
  r.add<AddOne>("AddOne");
  r.add<ParamProbe>("ParamProbe");
}

}  // namespace edm::test
