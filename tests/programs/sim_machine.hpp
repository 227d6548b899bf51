#pragma once
// Builds a Runtime for the programs' simulator tests: every built-in block and program type, the
// runtime's drivers and the simulator driver (registries built once, shared by all tests).

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "edm/sim/sim_driver.hpp"
#include "support/files.hpp"

namespace edm::test {

inline std::unique_ptr<rt::Runtime> build_sim_machine(const rt::Config& cfg,
                                                      const rt::BuildOptions& options = {}) {
  static const auto registries = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    blocks::register_builtin_blocks(r.first);
    programs::register_builtin_programs(r.first);
    rt::register_runtime_drivers(r.second);
    sim::register_sim_driver(r.second);
    return r;
  }();
  return rt::Runtime::build(cfg, registries.first, registries.second, options);
}

/// Build options that seed the simulator with `seed`.
inline rt::BuildOptions seeded(int seed) {
  rt::BuildOptions o;
  o.seed = static_cast<std::uint64_t>(seed);
  return o;
}

/// Powers `runtime` on and puts every task on `clock`, traces detached (nothing written).
inline std::unique_ptr<rt::VirtualScheduler> power_on_virtual(rt::Runtime& runtime,
                                                              rt::VirtualClock& clock) {
  runtime.machine().command(rt::MachineCommand::kPowerOn);
  std::vector<rt::Task*> tasks;
  for (const auto& t : runtime.tasks()) {
    t->detach_trace();
    tasks.push_back(t.get());
  }
  return std::make_unique<rt::VirtualScheduler>(tasks, clock);
}

// A shipped machine (config/machines/<name>.yaml) powered on, every task on one virtual clock
// (traces detached): `run_until(t)` runs all cycles released before t, `pin(name)` finds a
// variable's pin (a test failure, and an empty PinRef, if there is none).
struct VirtualMachine {
  std::unique_ptr<rt::Runtime> runtime;
  rt::VirtualClock clock;
  std::unique_ptr<rt::VirtualScheduler> sched;

  explicit VirtualMachine(const std::string& name, const rt::BuildOptions& options = {})
      : runtime(build_sim_machine(rt::parse_config_file(std::string(EDM_SOURCE_DIR) +
                                                        "/config/machines/" + name + ".yaml"),
                                  options)) {
    sched = power_on_virtual(*runtime, clock);
  }
  void run_until(rt::TimePoint t) { sched->run_until(t); }
  rt::VariableRegistry& vars() { return runtime->variables(); }
  rt::PinRef pin(const char* name) {
    const rt::Variable* v = runtime->variables().find(name);
    EXPECT_NE(v, nullptr) << name;
    return v != nullptr ? v->pin : rt::PinRef{};
  }
};

/// Replaces the first `from` in `s` by `to` (a test failure if `s` has none).
inline void replace_once(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

// A machine built from config text and powered on, its first task run one 1 ms cycle at a time on
// a virtual clock: `run_cycle(k)` runs cycle k (released at k ms), `cycle()` the next one. The
// trace is drained every 4096 cycles so that it never fills.
/// Seed 004's rule, asserted on every cycle it is shown (issue 19): while a drilling program's Td
/// window reads short (`<program>.gap_short`), or this cycle's own pulses do
/// (`<program>.cycle_short`, issue 31), its Z command (`<program>.vz_cmd_mm_s`) and the
/// machine's (`io.vz_cmd`) never point toward the work (down). Finds every such program of a
/// built machine; a machine without one checks nothing.
class ShortFeedWatch {
 public:
  explicit ShortFeedWatch(const rt::VariableRegistry& vars) {
    const rt::Variable* io = vars.find("io.vz_cmd");
    for (const rt::Variable& v : vars.all()) {
      const std::string suffix = ".gap_short";
      if (v.name.size() <= suffix.size() ||
          v.name.compare(v.name.size() - suffix.size(), suffix.size(), suffix) != 0) {
        continue;
      }
      const std::string base = v.name.substr(0, v.name.size() - suffix.size());
      const rt::Variable* vz = vars.find(base + ".vz_cmd_mm_s");
      const rt::Variable* cycle = vars.find(base + ".cycle_short");
      if (vz != nullptr && v.is_pin() && vz->is_pin()) {
        watched_.push_back({base, v.pin, cycle != nullptr ? cycle->pin : v.pin, vz->pin,
                            io != nullptr ? io->pin : vz->pin});
      }
    }
  }
  ShortFeedWatch(const ShortFeedWatch&) = delete;
  ShortFeedWatch& operator=(const ShortFeedWatch&) = delete;
  ~ShortFeedWatch() {
    EXPECT_EQ(violations_, 0) << "fed toward the work while the gap read short: " << first_;
  }
  void check(std::int64_t cycle) {
    for (const Watched& w : watched_) {
      if (rt::read_pin_as_double(w.gap_short) == 0.0 &&
          rt::read_pin_as_double(w.cycle_short) == 0.0) {
        continue;
      }
      if (rt::read_pin_as_double(w.vz) < 0.0 || rt::read_pin_as_double(w.io_vz) < 0.0) {
        if (violations_++ == 0) first_ = w.program + " at cycle " + std::to_string(cycle);
      }
    }
  }
  [[nodiscard]] std::size_t watched() const noexcept { return watched_.size(); }

 private:
  struct Watched {
    std::string program;
    rt::PinRef gap_short, cycle_short, vz, io_vz;
  };
  std::vector<Watched> watched_;
  std::int64_t violations_{0};
  std::string first_;
};

struct SteppedMachine {
  std::unique_ptr<rt::Runtime> runtime;
  rt::VirtualClock clock;
  rt::Task& task;
  rt::VariableRegistry& vars;
  std::int64_t next{0};  // the cycle cycle() runs
  std::ostringstream sink;

  ShortFeedWatch no_feed_while_short;

  SteppedMachine(const std::string& text, const std::string& name)
      : runtime(build_sim_machine(rt::parse_config_text(text, name))),
        task(*runtime->tasks()[0]),
        vars(runtime->variables()),
        no_feed_while_short(vars) {
    runtime->machine().command(rt::MachineCommand::kPowerOn);
  }
  void run_cycle(std::int64_t k) {
    const rt::TimePoint release{std::chrono::milliseconds(1) * k};
    clock.advance_to(release);
    task.run_cycle(release, clock);
    no_feed_while_short.check(k);
    if (k % 4096 == 0) runtime->trace().drain(sink), sink.str({});
  }
  void cycle() { run_cycle(next++); }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) cycle();
  }
  /// Runs cycles while `go_on()` holds, up to cycle `max_cycles` (counted from the first).
  template <class Pred>
  void run_while(std::int64_t max_cycles, Pred go_on) {
    while (next < max_cycles && go_on()) cycle();
  }
  double read(const char* name) { return vars.read(name).value(); }
  /// Forces the hold input `var` on and runs one cycle (false, and no cycle, if it cannot).
  bool hold(const char* var) {
    if (!vars.force(var, 1.0)) return false;
    cycle();
    return true;
  }
};

}  // namespace edm::test
