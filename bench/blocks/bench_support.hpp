#pragma once
// Shared by the block benchmarks (bench/blocks/*.cpp): wiring blocks by pin name, the non-RT
// start-up, and the two ways a cost is reported:
//   run_cycles  — for calls too short to time one by one (a few ns, like a steady_clock read):
//                 a timestamp every kBatch calls, p50_ns/p99_ns/max_ns over the batches' means;
//   run_timed   — for calls of ~100 ns and more: each call timed on its own with steady_clock
//                 (~20-30 ns of the reading is in the figure), p50_ns/p99_ns/max_ns per call.
// Both add their counters to the benchmark's; Time/CPU stay Google Benchmark's means.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <random>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::bench {

using namespace std::chrono_literals;

inline constexpr int kBatch = 64;
inline constexpr std::size_t kTableSize = 4096;  // power of two: index with a mask
inline constexpr rt::Duration kPeriod = 1ms;

inline const std::array<double, kTableSize>& input_table() {
  static const auto table = [] {
    std::array<double, kTableSize> t{};
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> d(-10.0, 10.0);
    for (double& x : t) {
      x = d(rng);
    }
    return t;
  }();
  return table;
}

// Finds a pin by name (the benchmark wires blocks the way the loader does, through visit_pins).
class PinFinder final : public rt::PinVisitor {
 public:
  explicit PinFinder(std::string_view name) : name_(name) {}
  rt::PinRef found;

 protected:
  void on_pin(std::string_view name, rt::PinRef ref, std::string_view /*unit*/) override {
    if (name == name_) {
      found = ref;
    }
  }

 private:
  std::string_view name_;
};

inline rt::PinRef pin_of(rt::Block& b, std::string_view name) {
  PinFinder f(name);
  b.visit_pins(f);
  return f.found;
}

// Non-RT setup in the runtime's order; aborts the benchmark on a configuration error.
template <class B>
bool start(benchmark::State& state, B& block, const typename B::Params& p) {
  block.set_params(p);
  if (!block.validate().empty() || !block.configure({"bench.block", kPeriod}).empty()) {
    state.SkipWithError("block configuration refused");
    return false;
  }
  block.commit_params();
  block.activate();
  return true;
}

// Nanosecond figures in buckets of `width` up to buckets × width, the exact maximum beyond
// (allocated at construction, before timing). A percentile is the largest value its bucket can
// hold, or the maximum when that is lower: whole nanoseconds (Value = std::int64_t, width 1)
// exactly, real ones within a bucket's width.
template <class Value>
class NsHistogram {
 public:
  NsHistogram(Value width, std::size_t buckets) : width_(width), counts_(buckets + 1, 0) {}
  void add(Value ns) {
    const auto bucket = static_cast<std::size_t>(std::max(ns, Value{0}) / width_);
    ++counts_[std::min(bucket, counts_.size() - 1)];
    ++total_;
    max_ns_ = std::max(max_ns_, ns);
  }
  [[nodiscard]] double percentile(double q) const {
    const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(total_));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i + 1 < counts_.size(); ++i) {
      seen += counts_[i];
      if (seen > rank) {
        const std::size_t top = std::is_integral_v<Value> ? i : i + 1;
        return std::min(static_cast<double>(top) * static_cast<double>(width_), max_ns());
      }
    }
    return max_ns();
  }
  [[nodiscard]] double max_ns() const { return static_cast<double>(max_ns_); }

 private:
  Value width_;
  std::vector<std::uint64_t> counts_;  // the last one: beyond the buckets
  std::uint64_t total_{0};
  Value max_ns_{0};
};

// Per-cycle means of the timed batches: 0.25 ns buckets up to 1 µs.
struct BatchHistogram : NsHistogram<double> {
  BatchHistogram() : NsHistogram(0.25, 4096) {}
};

// Per-call times in whole nanoseconds: 1 ns buckets up to 64 µs.
struct CallHistogram : NsHistogram<std::int64_t> {
  CallHistogram() : NsHistogram(1, 65536) {}
};

// Adds the figures of a histogram (BatchHistogram, CallHistogram) to the benchmark's counters.
template <class Histogram>
void report_percentiles(benchmark::State& state, const Histogram& hist) {
  state.counters["p50_ns"] = hist.percentile(0.50);
  state.counters["p99_ns"] = hist.percentile(0.99);
  state.counters["max_ns"] = hist.max_ns();
}

// Runs one_cycle once per benchmark iteration; see the file comment for what is reported.
template <class Fn>
void run_cycles(benchmark::State& state, Fn&& one_cycle) {
  BatchHistogram hist;
  int in_batch = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    one_cycle();
    if (++in_batch == kBatch) {
      const auto t1 = std::chrono::steady_clock::now();
      hist.add(std::chrono::duration<double, std::nano>(t1 - t0).count() / kBatch);
      t0 = t1;
      in_batch = 0;
    }
  }
  report_percentiles(state, hist);
}

// Runs one_call once per iteration and times each call on its own (see the file comment).
template <class Fn>
void run_timed(benchmark::State& state, Fn&& one_call) {
  CallHistogram hist;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    one_call();
    const auto t1 = std::chrono::steady_clock::now();
    hist.add(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
  }
  report_percentiles(state, hist);
}

// Times one_call on its own as this iteration's manual time (a benchmark with UseManualTime(),
// whose iteration does untimed work besides), into hist.
template <class Fn>
void time_manually(benchmark::State& state, CallHistogram& hist, Fn&& one_call) {
  const auto t0 = std::chrono::steady_clock::now();
  one_call();
  const auto t1 = std::chrono::steady_clock::now();
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0);
  hist.add(ns.count());
  state.SetIterationTime(std::chrono::duration<double>(ns).count());
}

/// A cycle context for a 1 ms task in RUNNING.
inline rt::CycleContext running_context() {
  rt::CycleContext ctx;
  ctx.period = kPeriod;
  ctx.dt_s = 1e-3;
  ctx.state = rt::MachineState::kRunning;
  return ctx;
}

/// One cycle of block b, for run_cycles or run_timed: inputs() sets the cycle's inputs (from
/// ctx.cycle, say), then b.update(ctx), then output `out` is read (neither is optimised away),
/// then ctx.cycle counts on. b and ctx outlive the returned callable.
template <class Inputs>
auto block_cycle(rt::Block& b, std::string_view out, rt::CycleContext& ctx, Inputs inputs) {
  return [&b, &ctx, pin = pin_of(b, out), inputs = std::move(inputs)]() mutable {
    inputs();
    benchmark::DoNotOptimize(b.update(ctx));
    benchmark::DoNotOptimize(rt::read_pin_as_double(pin));
    ++ctx.cycle;
  };
}

/// Connects the input `name` of b to `source` (false if b has no such input of type T).
template <class T>
bool wire(rt::Block& b, std::string_view name, rt::Output<T>& source) {
  auto* in = pin_of(b, name).template as_input<T>();
  if (in == nullptr) {
    return false;
  }
  in->connect(source);
  return true;
}
/// Sets the input `name` of b to a constant.
template <class T>
bool set_input(rt::Block& b, std::string_view name, T value) {
  auto* in = pin_of(b, name).template as_input<T>();
  if (in == nullptr) {
    return false;
  }
  in->set_constant(value);
  return true;
}

}  // namespace edm::bench
