#pragma once
// A machine for the safety supervisor's fault-injection tests: a config (a shipped machine,
// possibly edited, or YAML text) built with every block, program and driver type — the test
// blocks (Cost) included — powered on, on one virtual clock. step() runs one cycle of a 1 ms
// task; alarms() drains the machine's alarm queue into `seen` (kept, in order).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
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
#include "support/test_blocks.hpp"

namespace edm::test {

inline std::string shipped_config(const std::string& name) {
  std::ifstream in(std::string(EDM_SOURCE_DIR) + "/config/machines/" + name + ".yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A path beside the shipped machines: text parsed under it finds their fragments (`include:`).
inline std::string shipped_path(const std::string& name) {
  return std::string(EDM_SOURCE_DIR) + "/config/machines/" + name + ".yaml";
}

/// `text` with `from` replaced by `to` exactly once (a test failure otherwise).
inline std::string edited(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "not in the config: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The start of a config test about the safety section, up to its `safety:` key: a loopback
/// machine with `channels` channels of each kind and a Z axis. The section follows on line 8.
inline std::string safety_machine(int channels) {
  return R"(version: 1
machine:
  name: m
  io: {driver: loopback, params: {channels: )" +
         std::to_string(channels) + R"(}}
  axes:
    - {name: Z, min_mm: -60, max_mm: 20}
  safety:
)";
}

/// What follows the `machine:` section of a config test about the safety section: one 1 ms task
/// running one Gain block.
inline constexpr const char* kGainTask = R"(
tasks:
  - {name: fast, interval: 1ms, programs: [p]}
programs:
  - name: p
    blocks: [{name: g, type: Gain}]
)";

struct SafetyRig {
  std::unique_ptr<rt::Runtime> runtime;
  rt::VirtualClock clock;
  std::unique_ptr<rt::VirtualScheduler> sched;
  rt::TimePoint t{};
  std::vector<rt::Alarm> seen;

  explicit SafetyRig(const std::string& yaml, const std::string& path = shipped_path("rig")) {
    static const auto registries = [] {
      std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
      blocks::register_builtin_blocks(r.first);
      programs::register_builtin_programs(r.first);
      register_test_blocks(r.first);
      rt::register_runtime_drivers(r.second);
      sim::register_sim_driver(r.second);
      return r;
    }();
    runtime =
        rt::Runtime::build(rt::parse_config_text(yaml, path), registries.first, registries.second);
    runtime->machine().command(rt::MachineCommand::kPowerOn);
    std::vector<rt::Task*> tasks(runtime->tasks().size());
    std::transform(runtime->tasks().begin(), runtime->tasks().end(), tasks.begin(),
                   [](const std::unique_ptr<rt::Task>& task) {
                     task->detach_trace();  // nothing drains the rings here
                     return task.get();
                   });
    sched = std::make_unique<rt::VirtualScheduler>(std::move(tasks), clock);
  }

  rt::Machine& machine() { return runtime->machine(); }
  rt::MachineState state() { return runtime->machine().state(); }
  rt::VariableRegistry& vars() { return runtime->variables(); }
  double read(const char* name) {
    const auto v = runtime->variables().read(name);
    EXPECT_TRUE(v.has_value()) << name;
    return v.value_or(NAN);
  }
  /// One cycle of every task released in the next millisecond.
  void step() {
    t += std::chrono::milliseconds(1);
    sched->run_until(t);
  }
  void run_ms(int ms) {
    for (int k = 0; k < ms; ++k) step();
  }
  /// Steps until pred() holds, at most `max` cycles; returns how many it took (max + 1: never).
  template <class Pred>
  int step_until(Pred pred, int max) {
    for (int k = 1; k <= max; ++k) {
      step();
      if (pred()) return k;
    }
    return max + 1;
  }
  /// Drains the alarm queue into `seen`; returns how many of `code` were seen so far.
  std::size_t alarms(rt::AlarmCode code) {
    rt::Alarm a;
    while (runtime->machine().pop_alarm(a)) seen.push_back(a);
    std::size_t n = 0;
    for (const rt::Alarm& s : seen) n += s.code == code ? 1 : 0;
    return n;
  }
  /// The latched alarm (code, source), or one with count 0.
  rt::ActiveAlarm active(rt::AlarmCode code, const std::string& source) {
    std::array<rt::ActiveAlarm, rt::Machine::kLatchCapacity> all{};
    const std::size_t n = runtime->machine().active_alarms(all.data(), all.size());
    for (std::size_t k = 0; k < n; ++k) {
      if (all[k].code == code && source == all[k].source) return all[k];
    }
    return {};
  }
};

/// The first problem building `yaml` into a SafetyRig ("file:line:col: message"), or "accepted".
inline std::string first_build_error(const std::string& yaml, const std::string& path) {
  try {
    SafetyRig rig(yaml, path);
  } catch (const rt::ConfigError& e) {
    return e.diagnostics().front().str();
  }
  return "accepted";
}

}  // namespace edm::test
