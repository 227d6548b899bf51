#pragma once
// Runs a part program (motion blocks, as edmhmi's interpreter makes them) on a shipped simulated
// machine through the runtime's JobStore (the bridge's program.commit does the same), on a
// virtual clock, and reports the simulator's truth: true depth, wall radii, time, shorts.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "edm/machining/motion_block.hpp"
#include "edm/machining/program_check.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_machine.hpp"

namespace edm::test {

struct JobResult {
  bool finished{false};
  double depth_mm{0.0};
  double r0_mm{0.0}, r_min_mm{0.0}, r_max_mm{0.0};
  double z_end_mm{0.0};
  double time_s{0.0};
  double short_fraction{0.0};
};

// Runs `program` on the machine of config/machines/<machine> (1 ms motion task, 10 ms supervisor)
// until the job finishes or the machine faults; `on_cycle` sees the variables after every
// motion cycle; `before_start` sees the machine once it is built (e.g. to set the feed override).
template <class OnCycle, class BeforeStart>
inline JobResult run_job(int seed, const std::vector<machining::MotionBlock>& program,
                         machining::Vec3 start, const std::string& machine, OnCycle&& on_cycle,
                         BeforeStart&& before_start) {
  JobResult res;
  rt::BuildOptions opts;
  opts.seed = static_cast<std::uint64_t>(seed);
  // `machine`: a file of config/machines/, or a path (an experiment's own config).
  const std::string path = machine.find('/') != std::string::npos
                               ? machine
                               : std::string(EDM_SOURCE_DIR) + "/config/machines/" + machine;
  auto r = build_sim_machine(rt::parse_config_file(path), opts);
  const auto issues = machining::check_program(program, r->tables(), start);
  EXPECT_TRUE(issues.empty()) << issues[0].message;
  EXPECT_EQ(r->job().load(program), rt::LoadResult::kOk);
  r->machine().command(rt::MachineCommand::kPowerOn);
  before_start(*r);
  EXPECT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  const sim::Plant& plant = dynamic_cast<sim::SimDriver&>(r->driver()).plant();
  res.r0_mm = plant.wall_bin_radius_mm(0);
  auto& vars = r->variables();
  rt::VirtualClock clock;
  rt::Task& motion = *r->tasks()[0];
  rt::Task& supervisor = *r->tasks()[1];
  std::ostringstream sink;
  ShortFeedWatch no_feed_while_short(vars);
  EXPECT_EQ(no_feed_while_short.watched(), 1u) << "cnc.job.drill";
  double shorts = 0.0, pulses = 0.0;
  std::int64_t k = 0;
  for (; k < 300'000; ++k) {
    const rt::TimePoint t{std::chrono::milliseconds(1) * k};
    clock.advance_to(t);
    motion.run_cycle(t, clock);
    no_feed_while_short.check(k);
    if (k % 10 == 0) supervisor.run_cycle(t, clock);
    if (k % 4096 == 0) r->trace().drain(sink), sink.str({});
    on_cycle(vars);
    if (vars.read("cnc.job.drill.state").value() == 2.0) {
      shorts += vars.read("io.n_short").value();
      for (const char* n :
           {"io.n_open", "io.n_normal", "io.n_short", "io.n_transient_arc", "io.n_stable_arc"}) {
        pulses += vars.read(n).value();
      }
    }
    if (r->job().progress().outcome == rt::JobOutcome::kFinished) {
      res.finished = true;
      break;
    }
    if (rt::is_safe_state(r->machine().state())) break;
  }
  res.time_s = static_cast<double>(k) * 1e-3;
  res.depth_mm = vars.read("io.depth_mm").value();
  res.z_end_mm = vars.read("io.z_mm").value();
  res.short_fraction = pulses > 0 ? shorts / pulses : 0.0;
  res.r_min_mm = 1e9;
  res.r_max_mm = 0.0;
  for (int j = 0; j < 64; ++j) {
    res.r_min_mm = std::min(res.r_min_mm, plant.wall_bin_radius_mm(j));
    res.r_max_mm = std::max(res.r_max_mm, plant.wall_bin_radius_mm(j));
  }
  EXPECT_EQ(r->machine().state(), rt::MachineState::kReady)
      << "the job stops the machine; last alarm cause "
      << static_cast<int>(r->machine().last_cause());
  return res;
}

template <class OnCycle>
inline JobResult run_job(int seed, const std::vector<machining::MotionBlock>& program,
                         machining::Vec3 start, const std::string& machine, OnCycle&& on_cycle) {
  return run_job(seed, program, start, machine, std::forward<OnCycle>(on_cycle),
                 [](rt::Runtime&) {});
}

inline JobResult run_job(int seed, const std::vector<machining::MotionBlock>& program,
                         machining::Vec3 start) {
  return run_job(seed, program, start, "drill-sim.yaml", [](const auto&) {});
}

}  // namespace edm::test
