// Cost of one update() of each EDM block of seeds 000-004 (issue 23 item 7), through rt::Block&
// (a virtual call, as the task makes it), with inputs that change every call from seeded tables
// shaped like the signals the block sees on the simulated machines, and the parameters of the
// shipped config that uses it. Blocks of a few tens of ns report p50/p99 over batches of 64
// calls (run_cycles); the heavier ones (STR, self-tuning fuzzy PI, ILC cycle update) per call
// (run_timed). The seed-003 blocks (DischargeStateCounter, FuzzyServoLUT) are in
// blocks_bench.cpp; the whole drill-program scan in drill_scan_bench.cpp.

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>

#include "bench_support.hpp"
#include "edm/blocks/butterworth_low_pass.hpp"
#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/gap_controller_p.hpp"
#include "edm/blocks/grey_predictor_gm11.hpp"
#include "edm/blocks/iterative_learning_control.hpp"
#include "edm/blocks/linear_interpolator.hpp"
#include "edm/blocks/orbit_expander.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/self_tuning_fuzzy_pi.hpp"
#include "edm/blocks/self_tuning_regulator.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/blocks/wear_compensator.hpp"

namespace edm::blocks {
namespace {

using namespace edm::bench;

// A value in [lo, hi] from the seeded table (index masked: any cycle count works).
double table_in(std::uint64_t k, double lo, double hi) {
  return lo + (hi - lo) * (input_table()[k & (kTableSize - 1)] + 10.0) / 20.0;
}

// One cycle of the generator's counters at ~26 pulses per 1 ms cycle (20 µs on, 10 µs off, Td
// 2-20 µs), a few open and shorted pulses: what the drill's TdDetector reads from io.*.
struct PulseCounts {
  std::int64_t td_sum_ns, td_count, n_open, n_short;
};
const std::array<PulseCounts, kTableSize>& pulse_table() {
  static const auto table = [] {
    std::array<PulseCounts, kTableSize> t{};
    std::mt19937_64 rng(4004);
    std::uniform_int_distribution<std::int64_t> td_ns(2000, 20000);
    std::uniform_int_distribution<std::int64_t> few(0, 3);
    for (PulseCounts& c : t) {
      c.n_open = few(rng);
      c.n_short = few(rng) == 3 ? 1 : 0;
      c.td_count = 26 - c.n_open - c.n_short;
      c.td_sum_ns = 0;
      for (std::int64_t i = 0; i < c.td_count; ++i) {
        c.td_sum_ns += td_ns(rng);
      }
    }
    return t;
  }();
  return table;
}

// Seed 004: the Td detector over an 8-cycle window (drill-sim's), 5 counter pins per cycle.
void BM_TdDetector(benchmark::State& state) {
  TdDetector block;
  if (!start(state, block, TdDetectorParams{})) {
    return;
  }
  rt::Output<std::int64_t> sum, count, open, shorts;
  wire(block, "td_sum_ns", sum);
  wire(block, "td_count", count);
  wire(block, "n_open", open);
  wire(block, "n_short", shorts);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] {
    const PulseCounts& c = pulse_table()[ctx.cycle & (kTableSize - 1)];
    sum.set(c.td_sum_ns);
    count.set(c.td_count);
    open.set(c.n_open);
    shorts.set(c.n_short);
  };
  run_cycles(state, block_cycle(block, "td_us", ctx, inputs));
}

// Seed 004 eq. 1: Vz = Kg·(Tdr − Td), Td 2-20 µs around Tdr 8 µs (both clamps hit sometimes).
void BM_GapControllerP(benchmark::State& state) {
  GapControllerP block;
  if (!start(state, block, GapControllerPParams{})) {
    return;
  }
  rt::Output<double> td;
  wire(block, "td_us", td);
  set_input(block, "valid", true);
  set_input(block, "enable", true);
  set_input(block, "tdr_us", 8.0);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] { td.set(table_in(ctx.cycle, 2.0, 20.0)); };
  run_cycles(state, block_cycle(block, "vz_mm_s", ctx, inputs));
}

// Seed 004 eq. 8 with drill-sim's E1 (θ 0.6189, A_hole/A_e 1.3297): a servo that mostly feeds
// down and sometimes backs off (the high-water-mark branch and the compensating one both run).
void BM_WearCompensator(benchmark::State& state) {
  WearCompensator block;
  if (!start(state, block, WearCompensatorParams{})) {
    return;
  }
  rt::Output<double> vz;
  wire(block, "vz_in_mm_s", vz);
  set_input(block, "wear_ratio", 0.6189);
  set_input(block, "area_ratio", 1.3297);
  set_input(block, "enable", true);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] {
    ctx.release += kPeriod;  // it integrates over the time between releases
    vz.set(table_in(ctx.cycle, -0.8, 0.2));
  };
  run_cycles(state, block_cycle(block, "vz_out_mm_s", ctx, inputs));
}

// The inputs of an interpolator in these benchmarks: `start` toggling every cycle (ignored while
// busy, so a move that ends is followed by the next) and the override changing each cycle.
struct MoveDrive {
  rt::Output<bool> go;
  rt::Output<double> ovr;
  explicit MoveDrive(rt::Block& b) {
    wire(b, "start", go);
    wire(b, "override", ovr);
  }
  void set(std::uint64_t cycle) {
    go.set((cycle & 1) == 0);
    ovr.set(table_in(cycle, 0.5, 1.5));
  }
};

// Seed 004 eq. 12-13: a linear move in progress at 600 mm/min (MoveDrive's start and override).
void BM_LinearInterpolator(benchmark::State& state) {
  LinearInterpolator block;
  if (!start(state, block, LinearInterpolatorParams{})) {
    return;
  }
  MoveDrive drive(block);
  set_input(block, "lx_mm", 300.0);
  set_input(block, "ly_mm", -200.0);
  set_input(block, "lz_mm", -50.0);
  set_input(block, "feed_mm_min", 600.0);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] { drive.set(ctx.cycle); };
  run_cycles(state, block_cycle(block, "rx_mm", ctx, inputs));
}

// Seed 004 eq. 14-19: full circles of radius 1 mm at 600 mm/min (sin/cos every cycle).
void BM_CircularInterpolator(benchmark::State& state) {
  CircularInterpolator block;
  if (!start(state, block, CircularInterpolatorParams{})) {
    return;
  }
  MoveDrive drive(block);
  set_input(block, "i_mm", -1.0);
  set_input(block, "j_mm", 0.0);
  set_input(block, "full_circle", true);
  set_input<std::int64_t>(block, "turns", 100);
  set_input(block, "feed_mm_min", 600.0);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] { drive.set(ctx.cycle); };
  run_cycles(state, block_cycle(block, "rx_mm", ctx, inputs));
}

// Seed 004 eq. 20-21: the orbit radius grown from each revolution's mean Td (a revolution every
// 100 samples), towards a final radius it never reaches in the run.
void BM_OrbitExpander(benchmark::State& state) {
  OrbitExpanderParams p;
  p.samples_per_rev = 100;
  OrbitExpander block;
  if (!start(state, block, p)) {
    return;
  }
  rt::Output<bool> go;
  rt::Output<double> td;
  wire(block, "start", go);
  wire(block, "td_us", td);
  set_input(block, "r0_mm", 0.5);
  set_input(block, "final_radius_mm", 1e6);
  set_input(block, "enable", true);
  set_input(block, "valid", true);
  rt::CycleContext ctx = running_context();
  go.set(true);
  benchmark::DoNotOptimize(static_cast<rt::Block&>(block).update(ctx));
  const auto inputs = [&] { td.set(table_in(ctx.cycle, 2.0, 20.0)); };
  run_cycles(state, block_cycle(block, "radius_mm", ctx, inputs));
}

// One axis loop as EdmJob's px/py/pz run it (P + feed-forward, in-position window), following a
// reference that moves while the axis lags it by up to 50 µm.
void BM_PositionLoop(benchmark::State& state) {
  PositionLoop block;
  if (!start(state, block, PositionLoopParams{})) {
    return;
  }
  rt::Output<double> ref, x, vff;
  wire(block, "x_ref_mm", ref);
  wire(block, "x_mm", x);
  wire(block, "v_ff_mm_s", vff);
  set_input(block, "enable", true);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] {
    const double r = 1e-3 * static_cast<double>(ctx.cycle & 0xFFFF);
    ref.set(r);
    x.set(r - table_in(ctx.cycle, 0.0, 0.05));
    vff.set(table_in(ctx.cycle + 7, -1.0, 1.0));
  };
  run_cycles(state, block_cycle(block, "v_cmd_mm_s", ctx, inputs));
}

// Seed 001: one STR sample (sink-str-sim's parameters, the loops alternating): the five gap-state
// ratios in, an RLS update and the minimum-variance law out.
void BM_SelfTuningRegulator(benchmark::State& state) {
  SelfTuningRegulatorParams p;
  p.delay_v = 1;
  p.lambda = 0.97;
  p.ti_us = 100.0;
  p.us_per_unit_v = 60.0;
  p.u_v_initial = 1.1;
  p.to_initial_us = 50.0;
  p.to_min_us = 10.0;
  p.to_max_us = 300.0;
  p.y_rt_good = 0.7;
  p.k1_on_us = true;
  p.alternate = true;
  SelfTuningRegulator block;
  if (!start(state, block, p)) {
    return;
  }
  rt::Output<double> normal, transient, stable, shorts;
  wire(block, "ratio_normal", normal);
  wire(block, "ratio_transient_arc", transient);
  wire(block, "ratio_stable_arc", stable);
  wire(block, "ratio_short", shorts);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] {
    const double tr = table_in(ctx.cycle, 0.0, 0.15);
    const double st = ctx.cycle % 50 == 0 ? 0.05 : 0.0;
    const double sh = table_in(ctx.cycle + 11, 0.0, 0.1);
    transient.set(tr);
    stable.set(st);
    shorts.set(sh);
    normal.set(0.8 - tr - st - sh);
  };
  run_timed(state, block_cycle(block, "servo_ref_v", ctx, inputs));
}

// Seed 000: one step of the self-tuning fuzzy PI (wire-stfpi-sim's parameters): predicted and
// filtered arc ratios in, fuzzy self-tuning of the PI gains, two outputs.
void BM_SelfTuningFuzzyPI(benchmark::State& state) {
  SelfTuningFuzzyPIParams p;
  p.ge = 5.0;
  p.gce = 40.0;
  p.alpha = 0.7;
  p.ol = 3.0;
  p.ku = 0.07;
  p.kv = 0.14;
  p.rab_ref_default = 0.42;
  p.overload_error = 0.01;
  p.u_initial_us = 20.0;
  p.v_initial_v = 40.0;
  p.settle_samples = 0;
  SelfTuningFuzzyPI block;
  if (!start(state, block, p)) {
    return;
  }
  rt::Output<double> rab_p, rab_f;
  wire(block, "rab_p", rab_p);
  wire(block, "rab_f", rab_f);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] {
    rab_p.set(table_in(ctx.cycle, 0.2, 0.7));
    rab_f.set(table_in(ctx.cycle + 3, 0.3, 0.6));
  };
  run_timed(state, block_cycle(block, "arc_off_time_us", ctx, inputs));
}

// Seed 000 eq. 1: the GM(1,1) grey predictor, window 5, horizon 37, as wire-stfpi-sim runs it.
void BM_GreyPredictorGM11(benchmark::State& state) {
  GreyPredictorGM11Params p;
  p.window = 5;
  p.horizon = 37;
  p.paper_exp = true;
  p.out_min = 0.0;
  p.out_max = 1.0;
  GreyPredictorGM11 block;
  if (!start(state, block, p)) {
    return;
  }
  rt::Output<double> in;
  wire(block, "in", in);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] { in.set(table_in(ctx.cycle, 0.3, 0.6)); };
  run_cycles(state, block_cycle(block, "out", ctx, inputs));
}

// Seed 000: the 2nd-order Butterworth low-pass (cutoff 0.012 of Nyquist, wire-stfpi-sim's).
void BM_ButterworthLowPass(benchmark::State& state) {
  ButterworthLowPassParams p;
  p.cutoff = 0.012;
  ButterworthLowPass block;
  if (!start(state, block, p)) {
    return;
  }
  rt::Output<double> in;
  wire(block, "in", in);
  rt::CycleContext ctx = running_context();
  const auto inputs = [&] { in.set(table_in(ctx.cycle, 0.0, 1.0)); };
  run_cycles(state, block_cycle(block, "out", ctx, inputs));
}

// Seed 002's ILC with sink-ilc-sim's parameters (N = 1500 samples a jump cycle, Q pole 0.9, warm
// start over 2 cycles), learning (past the warm start).
IterativeLearningControlParams ilc_params() {
  IterativeLearningControlParams p;
  p.n_samples = 1500;
  p.p0 = 0.005;
  p.k_delta = 1290.0;
  p.q_pole = 0.9;
  p.lambda1 = 0.5;
  p.lambda2 = 0.5;
  p.lambda3 = 0.0997;
  p.u_initial = 0.05;
  p.u_min = -20.0;
  p.u_max = 5.0;
  p.warm_cycles = 2;
  p.e_max = 30.0;
  return p;
}

struct IlcRig {
  IterativeLearningControl block;
  rt::Output<double> y, track;
  rt::Output<bool> edge;
  rt::PinRef out;
  rt::CycleContext ctx = running_context();
  std::int64_t n{1500};

  bool setup(benchmark::State& state) {
    const IterativeLearningControlParams p = ilc_params();
    n = p.n_samples;
    if (!start(state, block, p)) {
      return false;
    }
    wire(block, "y", y);
    wire(block, "track", track);
    wire(block, "cycle_start", edge);
    set_input(block, "y_ref", 0.02);
    out = pin_of(block, "u");
    // Past the warm start: 4 whole cycles, untimed.
    for (std::int64_t k = 0; k < 4 * n + 1; ++k) {
      sample();
    }
    return true;
  }
  // One update: a cycle edge every n samples (the sample of the edge included).
  void sample() {
    const auto k = static_cast<std::int64_t>(ctx.cycle);
    edge.set(k % n == 0);
    y.set(table_in(ctx.cycle, 0.0, 0.04));
    track.set(-1e-3 * static_cast<double>(k % n));
    benchmark::DoNotOptimize(static_cast<rt::Block&>(block).update(ctx));
    benchmark::DoNotOptimize(rt::read_pin_as_double(out));
    ++ctx.cycle;
  }
};

// Every update: O(1) samples, and one O(N) learning update per 1500 (its batch's mean is 1/64
// of it: the p99 of batch means shows it, the per-call cost is BM_ILCCycleUpdate).
void BM_ILCSample(benchmark::State& state) {
  IlcRig rig;
  if (!rig.setup(state)) {
    return;
  }
  run_cycles(state, [&] { rig.sample(); });
}

// The learning update alone: the update() at a cycle edge, u_j+1 = Q·(u_j + L·e_j) over
// N = 1500 samples. Each iteration runs the 1499 samples of a cycle untimed, then times the edge
// (manual time: Time is the edge's cost alone).
void BM_ILCCycleUpdate(benchmark::State& state) {
  IlcRig rig;
  if (!rig.setup(state)) {
    return;
  }
  CallHistogram hist;
  for (auto _ : state) {
    while (static_cast<std::int64_t>(rig.ctx.cycle) % rig.n != 0) {
      rig.sample();
    }
    time_manually(state, hist, [&] { rig.sample(); });
  }
  report_percentiles(state, hist);
}

BENCHMARK(BM_TdDetector);
BENCHMARK(BM_GapControllerP);
BENCHMARK(BM_WearCompensator);
BENCHMARK(BM_LinearInterpolator);
BENCHMARK(BM_CircularInterpolator);
BENCHMARK(BM_OrbitExpander);
BENCHMARK(BM_PositionLoop);
BENCHMARK(BM_SelfTuningRegulator);
BENCHMARK(BM_SelfTuningFuzzyPI);
BENCHMARK(BM_GreyPredictorGM11);
BENCHMARK(BM_ButterworthLowPass);
BENCHMARK(BM_ILCSample);
BENCHMARK(BM_ILCCycleUpdate)->UseManualTime();

}  // namespace
}  // namespace edm::blocks
