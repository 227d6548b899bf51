#pragma once
// The drill machine (config/machines/drill-sim.yaml) with the work placed where the program does
// not know it (the simulator's work_* parameters) and incremental encoders, on a virtual clock:
// the rig of the operator functions' tests (issue 21). Requests go through the runtime's
// ManualControl exactly as the bridge's home / jog / touch ops send them.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "edm/machining/program_check.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/manual.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_machine.hpp"
#include "support/files.hpp"

namespace edm::test {

struct OperatorRig {
  std::unique_ptr<rt::Runtime> runtime;
  rt::VirtualClock clock;
  std::unique_ptr<rt::VirtualScheduler> sched;
  rt::TimePoint now{};
  std::uint64_t jobs_before_start{0};  // the job store's count when start_program() started one

  /// `sim_params`: extra simulator parameters ("work_surface_z_mm: -7.3, …"); `manual`: the
  /// job's manual child's parameters ("referenced_at_start: false, …"); `machine`: a drill
  /// machine of config/machines/ (its job block `job`, EdmJob).
  OperatorRig(const std::string& sim_params, const std::string& manual, int seed = 1,
              const std::string& machine = "drill-sim") {
    const std::string dir = std::string(EDM_SOURCE_DIR) + "/config/machines/";
    std::string text = read_file(dir + machine + ".yaml");
    replace_once(text, "params: {preset: drill, seed: 1, wall_sparks: true}",
                 "params: {preset: drill, seed: 1, wall_sparks: true" +
                     (sim_params.empty() ? std::string() : ", " + sim_params) + "}");
    if (text.find("manual: {}") != std::string::npos) {
      replace_once(text, "manual: {}", "manual: {" + manual + "}");
    } else {  // a job with no parameters (drill-fuzzy-sim)
      replace_once(text, "{name: job, type: EdmJob}",
                   "{name: job, type: EdmJob, params: {manual: {" + manual + "}}}");
    }
    // Parsed as if beside the shipped machines, so that their fragments are found.
    runtime = build_sim_machine(rt::parse_config_text(text, dir + machine + "-operator.yaml"),
                                seeded(seed));
    sched = power_on_virtual(*runtime, clock);
    run_for(std::chrono::milliseconds(5));
  }

  void run_for(rt::Duration d) {
    now += d;
    sched->run_until(now);
  }
  rt::ManualControl& manual() { return runtime->manual(); }
  const sim::PlantState& truth() {
    return dynamic_cast<sim::SimDriver&>(runtime->driver()).plant().state();
  }
  double read(const char* name) { return runtime->variables().read(name).value_or(1e9); }

  /// Sends `r` and runs until the runtime has taken it and is no longer busy (at most `limit`).
  rt::ManualResult request(rt::ManualRequest r, rt::Duration limit = std::chrono::seconds(120)) {
    const std::uint64_t seq = manual().request(r);
    const rt::TimePoint end = now + limit;
    while (now < end) {
      run_for(std::chrono::milliseconds(1));
      const rt::ManualStatus s = manual().status();
      if (s.seen_seq >= seq && !s.busy) return s.result;
    }
    ADD_FAILURE() << "manual request " << seq << " still busy after the limit";
    return manual().status().result;
  }
  rt::ManualResult home(std::uint8_t axes = 0x7) {
    rt::ManualRequest r;
    r.op = rt::ManualOp::kHome;
    r.axes = axes;
    return request(r);
  }
  rt::ManualResult jog(int axis, double mm) {
    rt::ManualRequest r;
    r.op = rt::ManualOp::kJogDistance;
    r.axis = static_cast<std::uint8_t>(axis);
    r.value = mm;
    return request(r);
  }
  /// Checks `blocks` from the current position as program.commit does, loads them into `slot`
  /// and starts them; false (a test failure) when refused.
  bool start_program(std::vector<machining::MotionBlock> blocks, rt::JobSlot slot) {
    const machining::Vec3 at{read("io.x_mm"), read("io.y_mm"), read("io.z_mm")};
    machining::ProgramCheckOptions check;
    check.electrode_mm = runtime->electrode().length_mm();  // as program.commit checks
    const auto issues = machining::check_program(blocks, runtime->tables(), at, check);
    EXPECT_TRUE(issues.empty()) << "line " << issues.front().line << ": " << issues.front().message;
    if (!issues.empty()) return false;
    auto& job = runtime->job();
    const auto loaded =
        slot == rt::JobSlot::kMdi ? job.load_mdi(std::move(blocks)) : job.load(std::move(blocks));
    EXPECT_EQ(loaded, rt::LoadResult::kOk);
    job.set_start_options({slot, false});
    jobs_before_start = job.progress().jobs_started;
    const auto started = runtime->machine().command(rt::MachineCommand::kStart);
    EXPECT_EQ(started, rt::CommandResult::kOk);
    return loaded == rt::LoadResult::kOk && started == rt::CommandResult::kOk;
  }
  /// Runs until the started job has ended (or `limit`, or a safe state); true when it finished.
  bool run_to_end(rt::Duration limit = std::chrono::seconds(600)) {
    auto& job = runtime->job();
    const rt::TimePoint end = now + limit;
    while (now < end && !rt::is_safe_state(runtime->machine().state())) {
      run_for(std::chrono::milliseconds(10));
      if (job.progress().jobs_started > jobs_before_start && !job.active()) break;
    }
    return job.progress().outcome == rt::JobOutcome::kFinished;
  }
  /// Checks `blocks` from the current position as program.commit does, loads them into `slot`,
  /// starts and runs until the job ends (or `limit`); true when it finished.
  bool run_program(std::vector<machining::MotionBlock> blocks, rt::JobSlot slot,
                   rt::Duration limit = std::chrono::seconds(600)) {
    return start_program(std::move(blocks), slot) && run_to_end(limit);
  }
  rt::ManualResult touch(rt::TouchTarget t) {
    rt::ManualRequest r;
    r.op = rt::ManualOp::kTouch;
    r.target = t;
    return request(r);
  }
};

}  // namespace edm::test
