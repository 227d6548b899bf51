// Interpreter throughput (issue 5): lines of G-code per second through interpret_gcode(), soft
// limits and conditions of the shipped drill machine included (the same check_program the runtime
// runs at commit). The program is generated: a row of holes, each a rapid approach, E1 with
// M03/M08, a gap-controlled drill, a retract, two arcs (G03 then G02) around the hole, a G04 dwell
// and M09/M05, with N numbers and comments, about 12 lines a hole, ended by M30.
//
// One iteration interprets the whole program; lines_per_s and blocks_per_s are rates over all
// iterations (Google Benchmark kIsRate), Time is per program.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"

namespace edm::hmi {
namespace {

/// A program of at least `min_lines` lines (whole holes), and its line count.
std::string make_program(int min_lines, int& lines) {
  std::string out = "%\n(generated: interpreter throughput benchmark)\n";
  lines = 2;
  char buf[160];
  int n = 10;
  auto add = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    out += buf;
    out += '\n';
    ++lines;
  };
  for (int hole = 0; lines < min_lines - 1; ++hole) {
    const double x = -80.0 + 2.0 * (hole % 80);
    const double y = -80.0 + 2.0 * ((hole / 80) % 80);
    add("N%d G00 Z5", n++);
    add("N%d G00 X%.3f Y%.3f ; next hole", n++, x, y);
    add("N%d E1 M03 M08", n++);
    add("N%d G01 Z-10 F60 (gap-controlled drill)", n++);
    add("N%d G01 Z5 F600", n++);
    add("N%d E0", n++);
    add("N%d G01 X%.3f", n++, x + 2.0);
    add("N%d G03 X%.3f Y%.3f I-2 J0", n++, x, y + 2.0);
    add("N%d G02 X%.3f Y%.3f I0 J-2", n++, x + 2.0, y);
    add("N%d G04 P0.01", n++);
    add("N%d M09", n++);
    add("N%d M05", n++);
  }
  add("N%d M30", n);
  return out;
}

void BM_InterpretProgram(benchmark::State& state) {
  const machining::MachineTables tables = machining::read_machine_tables(
      std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  int lines = 0;
  const std::string program = make_program(static_cast<int>(state.range(0)), lines);
  std::size_t blocks = 0;
  for (auto _ : state) {
    GcodeResult r = interpret_gcode(program, "bench.nc", tables);
    if (!r.ok()) {
      state.SkipWithError(r.messages().front().c_str());
      break;
    }
    blocks = r.blocks.size();
    benchmark::DoNotOptimize(r.blocks.data());
  }
  const auto its = static_cast<double>(state.iterations());
  state.counters["lines"] = lines;
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["lines_per_s"] = benchmark::Counter(lines * its, benchmark::Counter::kIsRate);
  state.counters["blocks_per_s"] =
      benchmark::Counter(static_cast<double>(blocks) * its, benchmark::Counter::kIsRate);
  state.SetBytesProcessed(static_cast<std::int64_t>(program.size() * state.iterations()));
}

BENCHMARK(BM_InterpretProgram)->Arg(100'000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace edm::hmi
