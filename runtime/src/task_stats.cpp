#include "edm/runtime/task_stats.hpp"

#include <algorithm>

namespace edm::rt {
namespace {

constexpr double to_us(std::int64_t ns) noexcept { return static_cast<double>(ns) * 1e-3; }

// Extremes: TaskStats's private {min_ns, max_ns, sum_ns}.
template <class Extremes>
DurationSummary summarize(const Extremes& raw, std::uint64_t cycles,
                          const LatencyHistogram& histogram) {
  if (cycles == 0) {
    return {};
  }
  // The histogram may be a few cycles newer than the scalars and is bucketed: keep the
  // percentiles consistent with the exact extremes of this snapshot.
  const auto in_range = [&](std::int64_t ns) { return std::clamp(ns, raw.min_ns, raw.max_ns); };
  return DurationSummary{
      .min_us = to_us(raw.min_ns),
      .avg_us = static_cast<double>(raw.sum_ns) / static_cast<double>(cycles) * 1e-3,
      .p50_us = to_us(in_range(histogram.quantile(0.50))),
      .p99_us = to_us(in_range(histogram.quantile(0.99))),
      .max_us = to_us(raw.max_ns),
  };
}

}  // namespace

void TaskStats::record_cycle(Duration latency, Duration exec) noexcept {
  const std::int64_t latency_ns = latency.count();
  const std::int64_t exec_ns = exec.count();
  // Histograms first, outside the seqlock: a reader sees them at least as new as the scalars.
  exec_histogram_.record(exec_ns);
  latency_histogram_.record(latency_ns);

  const auto update = [first = own_.cycles == 0](Extremes& e, std::int64_t ns) noexcept {
    e.min_ns = first ? ns : std::min(e.min_ns, ns);
    e.max_ns = first ? ns : std::max(e.max_ns, ns);
    e.sum_ns += ns;
  };
  update(own_.exec, exec_ns);
  update(own_.latency, latency_ns);
  ++own_.cycles;
  published_.store(own_);
}

void TaskStats::record_overrun(std::uint64_t omitted_cycles) noexcept {
  ++own_.overruns;
  own_.omitted_cycles += omitted_cycles;
  published_.store(own_);
}

TaskStatsSnapshot TaskStats::snapshot() const {
  const Scalars s = published_.load();
  TaskStatsSnapshot out;
  out.cycles = s.cycles;
  out.overruns = s.overruns;
  out.omitted_cycles = s.omitted_cycles;
  out.exec = summarize(s.exec, out.cycles, exec_histogram_);
  out.latency = summarize(s.latency, out.cycles, latency_histogram_);
  return out;
}

void TaskStats::reset() noexcept {
  own_ = {};
  exec_histogram_.reset();
  latency_histogram_.reset();
  // Advances the version: a snapshot started before the reset cannot validate against it.
  published_.reset(own_);
}

}  // namespace edm::rt
