// One whole scan of the drill program (issue 23 item 7): the machine of
// config/machines/drill-sim.yaml — EdmJob with its children (DeepHoleDrill: Td detector, P gap
// controller, wear compensator, short guard; interpolators, position loops, ManualMotion), the
// safety supervisor, statistics and watchdog — running examples/parts/demo.nc, timed while the
// job drills. Without the simulator: the I/O driver is BenchGapDriver below, a few lines of
// arithmetic that give the counters the generator would (≈ 26 pulses per cycle, Td from the
// frontal gap with seeded noise, some arcs and shorts) and integrate the axes' commands, so the
// time measured is the runtime's and the programs', not the plant model's.
//
//   BM_DrillScan_TaskCycle  Task::run_cycle of the 1 ms motion task on the real clock, as edmplc
//                           runs it: parameter queue, safe-state check, latch inputs, the cnc
//                           program, the supervisor, publish outputs, statistics, watchdog (with
//                           its thread-CPU-clock read, the host-stall check).
//   BM_DrillScan_EdmJob     the cnc program alone (EdmJob.update() and its children; manual time:
//                           the driver's latch and publish around it are not in the figure).
// Each call is timed on its own (run_timed): p50_ns / p99_ns / max_ns per scan. The setup runs
// the job (rapids, approach, first sparks) until the drill is in DRILL, and checks it is still
// drilling after the timed loop (SkipWithError otherwise).

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "bench_support.hpp"
#include "edm/blocks/register.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/xyz_pins.hpp"

namespace edm::bench {
namespace {

constexpr double kDrillState = 2.0;  // DeepHoleDrill's DRILL

// A stand-in for the generator and the axes: perfect axes (x += v·dt), a surface at Z 0 that
// recedes at 0.01 mm/s while sparking (the hole never reaches its depth during the benchmark),
// Td = 8 µs at a 27 µm frontal gap, proportional, ±30 % seeded noise; open beyond 60 µm; a short
// at contact and one shorted pulse every 50th cycle; ~6 % transient arcs.
class BenchGapDriver final : public rt::IoDriver {
 public:
  void read_inputs(const rt::CycleContext& ctx) noexcept override {
    const double gap_um = (z_ - surface_z_) * 1000.0;
    const std::uint64_t k = ctx.cycle;
    std::int64_t opens = 0, shorts = 0, normal = 0, arcs = 0, ignited = 0, sum_ns = 0;
    if (gen_on.get()) {
      if (gap_um > 60.0) {
        opens = 33;
      } else if (gap_um <= 0.0) {
        shorts = 33;
      } else {
        const double noise = 0.7 + 0.6 * (input_table()[k & (kTableSize - 1)] + 10.0) / 20.0;
        const double td_us = 8.0 * gap_um / 27.0 * noise;
        const auto n = static_cast<std::int64_t>(1000.0 / (30.0 + td_us));
        shorts = k % 50 == 0 ? 1 : 0;
        arcs = n / 16;
        normal = n - arcs - shorts;
        ignited = normal + arcs;
        sum_ns = static_cast<std::int64_t>(static_cast<double>(ignited) * td_us * 1000.0);
      }
    }
    sparking_ = ignited > 0;
    td_sum_ns.set(sum_ns);
    this->td_count.set(ignited);
    this->n_open.set(opens);
    this->n_short.set(shorts);
    this->n_normal.set(normal);
    n_transient_arc.set(arcs);
    const std::int64_t total = opens + shorts + normal + arcs;
    ratio_short.set(total > 0 ? static_cast<double>(shorts) / static_cast<double>(total) : 0.0);
    gap_voltage_v.set(opens > 0 ? 100.0 : 40.0);
    pos.x().set(x_);
    pos.y().set(y_);
    pos.z().set(z_);
    contact.set(gap_um <= 0.0);
  }
  void write_outputs(const rt::CycleContext& ctx) noexcept override {
    if (rt::is_safe_state(ctx.state)) {
      return;  // axes stopped
    }
    x_ += v_cmd.x().get() * ctx.dt_s;
    y_ += v_cmd.y().get() * ctx.dt_s;
    z_ += v_cmd.z().get() * ctx.dt_s;
    if (sparking_) {
      surface_z_ -= 0.01 * ctx.dt_s;
    }
  }

  // The process image, named as the simulator names it (drill-sim.yaml wires these).
  rt::Output<std::int64_t> td_sum_ns{pins_, "td_sum_ns", "ns"};
  rt::Output<std::int64_t> td_count{pins_, "td_count"};
  rt::Output<std::int64_t> n_open{pins_, "n_open"};
  rt::Output<std::int64_t> n_normal{pins_, "n_normal"};
  rt::Output<std::int64_t> n_transient_arc{pins_, "n_transient_arc"};
  rt::Output<std::int64_t> n_stable_arc{pins_, "n_stable_arc"};
  rt::Output<std::int64_t> n_short{pins_, "n_short"};
  rt::Output<double> ratio_short{pins_, "ratio_short", "1"};
  rt::Output<double> gap_voltage_v{pins_, "gap_voltage_v", "V"};
  rt::Xyz<rt::Output<double>> pos{pins_, {"x_mm", "y_mm", "z_mm"}, "mm"};
  rt::Output<double> electrode_mm{pins_, "electrode_mm", "mm", 300.0};
  rt::Xyz<rt::Output<bool>> ref{pins_, {"ref_x", "ref_y", "ref_z"}};
  rt::Output<bool> contact{pins_, "contact"};
  rt::Xyz<rt::Input<double>> v_cmd{pins_, {"vx_cmd", "vy_cmd", "vz_cmd"}, "mm/s"};
  rt::Input<bool> gen_arm{pins_, "gen_arm"};
  rt::Input<bool> gen_on{pins_, "gen_on"};
  rt::Input<bool> polarity_positive{pins_, "polarity_positive"};
  rt::Input<double> on_time_us{pins_, "on_time_us", "us"};
  rt::Input<double> off_time_us{pins_, "off_time_us", "us"};
  rt::Input<double> servo_ref_v{pins_, "servo_ref_v", "V"};
  rt::Input<bool> flushing_on{pins_, "flushing_on"};
  rt::Input<bool> rotation_on{pins_, "rotation_on"};
  rt::Input<bool> touch_mode{pins_, "touch_mode"};
  rt::Xyz<rt::Input<bool>> pos_set{pins_, {"pos_set_x", "pos_set_y", "pos_set_z"}};
  rt::Xyz<rt::Input<double>> pos_value{
      pins_, {"pos_value_x_mm", "pos_value_y_mm", "pos_value_z_mm"}, "mm"};

 private:
  double x_{0.0}, y_{0.0}, z_{5.0};  // the demo starts clear of the work
  double surface_z_{0.0};
  bool sparking_{false};
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// drill-sim.yaml with BenchGapDriver for the simulator, running demo.nc, stepped to DRILL.
struct DrillMachine {
  std::unique_ptr<rt::Runtime> runtime;
  rt::Task* motion{nullptr};
  rt::Program* cnc{nullptr};
  rt::RealClock clock;
  rt::TimePoint release{};
  std::uint64_t cycle{0};

  // Empty when the machine drills; else why not.
  std::string setup() {
    static const auto registries = [] {
      std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
      blocks::register_builtin_blocks(r.first);
      programs::register_builtin_programs(r.first);
      r.second.add<BenchGapDriver>("bench_gap");
      return r;
    }();
    const std::string machine = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";
    rt::Config cfg = rt::parse_config_file(machine);
    cfg.machine.io.driver = "bench_gap";
    cfg.machine.io.params.clear();   // the simulator's preset and seed
    cfg.trace.variables.clear();     // simulator truths (io.depth_mm, …) and no trace file
    cfg.retain = rt::RetainSpec{};   // nothing written
    cfg.bridge.status_vars.clear();  // no bridge here
    runtime = rt::Runtime::build(cfg, registries.first, registries.second);
    motion = runtime->tasks()[0].get();
    cnc = runtime->program("cnc");
    for (const auto& t : runtime->tasks()) {
      t->detach_trace();
    }
    hmi::GcodeOptions o;
    o.start_mm = {0.0, 0.0, 5.0};
    const auto g =
        hmi::interpret_gcode(read_text(std::string(EDM_SOURCE_DIR) + "/examples/parts/demo.nc"),
                             "demo.nc", machining::read_machine_tables(machine), o);
    if (!g.ok()) {
      return "demo.nc: " + g.messages()[0];
    }
    if (runtime->job().load(g.blocks) != rt::LoadResult::kOk) {
      return "the job store refused demo.nc";
    }
    runtime->machine().command(rt::MachineCommand::kPowerOn);
    if (runtime->machine().command(rt::MachineCommand::kStart) != rt::CommandResult::kOk) {
      return "cycle start refused";
    }
    release = clock.now();
    // Rapids over the hole, down to Z0.5, E1, the approach to the first sparks: ≈ 2 s.
    for (int k = 0; k < 60'000 && !drilling(); ++k) {
      step();
    }
    for (int k = 0; k < 2'000; ++k) {  // settle into the gap
      step();
    }
    return drilling() ? std::string{} : "the job never reached DRILL (state " + state_text() + ")";
  }
  [[nodiscard]] bool drilling() {
    return runtime->machine().state() == rt::MachineState::kRunning &&
           runtime->variables().read("cnc.job.drill.state").value_or(-1.0) == kDrillState;
  }
  [[nodiscard]] std::string state_text() {
    std::ostringstream s;
    s << "machine " << static_cast<int>(runtime->machine().state()) << ", drill "
      << runtime->variables().read("cnc.job.drill.state").value_or(-1.0) << ", job line "
      << runtime->variables().read("cnc.job.line").value_or(-1.0);
    return s.str();
  }
  // One motion-task cycle on the 1 ms grid (the 10 ms supervisor task is not part of the scan).
  void step() {
    release += kPeriod;
    motion->run_cycle(release, clock);
    ++cycle;
  }
};

void BM_DrillScan_TaskCycle(benchmark::State& state) {
  DrillMachine m;
  if (const std::string why = m.setup(); !why.empty()) {
    state.SkipWithError(why.c_str());
    return;
  }
  run_timed(state, [&] { m.step(); });
  if (!m.drilling()) {
    state.SkipWithError(("left DRILL during the timed loop: " + m.state_text()).c_str());
  }
  // Evidence that it drilled: the gap held near Tdr, the depth estimate growing.
  auto& vars = m.runtime->variables();
  state.counters["td_us"] = vars.read("cnc.job.drill.td.td_us").value_or(-1.0);
  state.counters["depth_um"] = 1e3 * vars.read("cnc.job.drill.depth_reached_mm").value_or(-1.0);
  state.counters["host_stalls"] = static_cast<double>(m.motion->host_stalls());
}

void BM_DrillScan_EdmJob(benchmark::State& state) {
  DrillMachine m;
  if (const std::string why = m.setup(); !why.empty()) {
    state.SkipWithError(why.c_str());
    return;
  }
  // The task's cycle as in run_cycle, with only the program's run timed.
  rt::IoDriver& io = m.runtime->driver();
  rt::CycleContext ctx = running_context();
  ctx.clock = &m.clock;
  CallHistogram hist;
  for (auto _ : state) {
    m.release += kPeriod;
    ctx.release = m.release;
    ctx.cycle = m.cycle++;
    ctx.state = m.runtime->machine().state();
    io.read_inputs(ctx);
    time_manually(state, hist, [&] { m.cnc->run(ctx); });
    io.write_outputs(ctx);
  }
  report_percentiles(state, hist);
  if (!m.drilling()) {
    state.SkipWithError(("left DRILL during the timed loop: " + m.state_text()).c_str());
  }
}

BENCHMARK(BM_DrillScan_TaskCycle);
BENCHMARK(BM_DrillScan_EdmJob)->UseManualTime();

}  // namespace
}  // namespace edm::bench
