#pragma once
// The wire machine (config/machines/wire-sim.yaml) running a part program as edmhmi does: the
// G-code interpreted against the machine's tables, loaded into the job store, run on a virtual
// clock; the part measured from the simulator's truth (the plate's material field).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_machine.hpp"

namespace edm::test {

inline std::string wire_config_path() {
  return std::string(EDM_SOURCE_DIR) + "/config/machines/wire-sim.yaml";
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A square punch's size measured on the truth: its width along X at y = cy ± 2.5 mm and along Y
/// at x = cx ± 2.5 mm (away from the lead-in), the smallest and largest of each, and how far its
/// corner lies from the centre along the diagonal.
struct PunchSize {
  double x_min{1e9}, x_max{0.0}, y_min{1e9}, y_max{0.0};
  double corner_mm{0.0};
};

inline PunchSize measure_punch(const sim::WirePlane& plane, double cx, double cy) {
  PunchSize s;
  for (double off : {-2.5, 2.5}) {
    const double wx =
        plane.edge_along_mm(cx, cy + off, 1, 0, 20) + plane.edge_along_mm(cx, cy + off, -1, 0, 20);
    const double wy =
        plane.edge_along_mm(cx + off, cy, 0, 1, 20) + plane.edge_along_mm(cx + off, cy, 0, -1, 20);
    s.x_min = std::min(s.x_min, wx);
    s.x_max = std::max(s.x_max, wx);
    s.y_min = std::min(s.y_min, wy);
    s.y_max = std::max(s.y_max, wy);
  }
  const double r = 1.0 / std::sqrt(2.0);
  s.corner_mm = plane.edge_along_mm(cx, cy, r, r, 20);
  return s;
}

struct WireRun {
  std::unique_ptr<rt::Runtime> runtime;
  rt::VirtualClock clock;
  std::int64_t k{0};
  bool finished{false};

  WireRun(int seed, const std::string& gcode, const std::string& config = wire_config_path()) {
    rt::BuildOptions opts;
    opts.seed = static_cast<std::uint64_t>(seed);
    runtime = build_sim_machine(rt::parse_config_file(config), opts);
    hmi::GcodeOptions o;
    o.start_mm = {-9, 0, 0};
    const auto g =
        hmi::interpret_gcode(gcode, "part.nc", machining::read_machine_tables(config), o);
    EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.messages()[0]);
    EXPECT_EQ(runtime->job().load(g.blocks), rt::LoadResult::kOk);
    runtime->machine().command(rt::MachineCommand::kPowerOn);
  }
  /// Where the job is, for a failure's message.
  std::string where() {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "at %.1f s: state %d cause %d line %.0f x %.4f y %.4f path speed %.4f back %.4f",
                  static_cast<double>(k) * 1e-3, static_cast<int>(runtime->machine().state()),
                  static_cast<int>(runtime->machine().last_cause()), read("cnc.job.line"),
                  read("io.x_mm"), read("io.y_mm"), read("cnc.job.wire.path_speed_mm_s"),
                  read("cnc.job.wire.back_mm"));
    return buf;
  }
  sim::Plant& plant() { return dynamic_cast<sim::SimDriver&>(runtime->driver()).plant(); }
  rt::VariableRegistry& vars() { return runtime->variables(); }
  double read(const char* name) { return vars().read(name).value(); }

  /// Starts the job and runs it until it finishes, the machine falls into a safe state, or
  /// `limit_s` (100 ms after a safe state began); M00/M01 holds are resumed at once. `each` sees
  /// every motion cycle.
  void run(double limit_s, const std::function<void(WireRun&)>& each = {}) {
    EXPECT_EQ(runtime->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
    rt::Task& motion = *runtime->tasks()[0];
    rt::Task& supervisor = *runtime->tasks()[1];
    std::ostringstream sink;
    const auto end = static_cast<std::int64_t>(limit_s * 1000.0);
    int safe_cycles = 0;  // a safe state runs on 100 ms (the job's abort, the axes stopping)
    for (; k < end; ++k) {
      const rt::TimePoint t{std::chrono::milliseconds(1) * k};
      clock.advance_to(t);
      motion.run_cycle(t, clock);
      if (k % 10 == 0) supervisor.run_cycle(t, clock);
      if (k % 4096 == 0) runtime->trace().drain(sink), sink.str({});
      if (each) each(*this);
      if (runtime->machine().state() == rt::MachineState::kHold) {
        runtime->machine().command(rt::MachineCommand::kResume);
      }
      if (runtime->job().progress().outcome == rt::JobOutcome::kFinished) {
        finished = true;
        break;
      }
      if (rt::is_safe_state(runtime->machine().state()) && ++safe_cycles > 100) break;
    }
  }
};

}  // namespace edm::test
