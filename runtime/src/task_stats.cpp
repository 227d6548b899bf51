#include "edm/runtime/task_stats.hpp"

#include <algorithm>
#include <thread>

namespace edm::rt {
namespace {

// Seqlock data accesses are release stores / acquire loads rather than relaxed accesses framed by
// std::atomic_thread_fence: equally correct, free on x86, and GCC rejects fences under
// -fsanitize=thread (-Wtsan, an error with EDM_WERROR) while TSan models acquire/release exactly.
template <class T>
void publish(std::atomic<T>& field, T value) noexcept {
  field.store(value, std::memory_order_release);
}
template <class T>
T peek(const std::atomic<T>& field) noexcept {
  return field.load(std::memory_order_acquire);
}
// The writer reads back only its own values: no ordering needed.
template <class T>
T own(const std::atomic<T>& field) noexcept {
  return field.load(std::memory_order_relaxed);
}

struct RawExtremes {
  std::int64_t min_ns{0};
  std::int64_t max_ns{0};
  std::int64_t sum_ns{0};
};

constexpr double to_us(std::int64_t ns) noexcept { return static_cast<double>(ns) * 1e-3; }

DurationSummary summarize(const RawExtremes& raw, std::uint64_t cycles,
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

void TaskStats::begin_write() noexcept {
  // Odd: readers that overlap this section retry. The data stores that follow are releases, so
  // a reader that sees any of them also sees this odd value when it re-reads seq_.
  seq_.store(own(seq_) + 1, std::memory_order_relaxed);
}

void TaskStats::end_write() noexcept { seq_.store(own(seq_) + 1, std::memory_order_release); }

void TaskStats::record_cycle(Duration latency, Duration exec) noexcept {
  const std::int64_t latency_ns = latency.count();
  const std::int64_t exec_ns = exec.count();
  // Histograms first, outside the seqlock: a reader sees them at least as new as the scalars.
  exec_histogram_.record(exec_ns);
  latency_histogram_.record(latency_ns);

  const std::uint64_t cycles = own(cycles_);
  const auto update = [first = cycles == 0](Extremes& e, std::int64_t ns) noexcept {
    publish(e.min_ns, first ? ns : std::min(own(e.min_ns), ns));
    publish(e.max_ns, first ? ns : std::max(own(e.max_ns), ns));
    publish(e.sum_ns, own(e.sum_ns) + ns);
  };
  begin_write();
  update(exec_, exec_ns);
  update(latency_, latency_ns);
  publish(cycles_, cycles + 1);
  end_write();
}

void TaskStats::record_overrun(std::uint64_t omitted_cycles) noexcept {
  begin_write();
  publish(overruns_, own(overruns_) + 1);
  publish(omitted_cycles_, own(omitted_cycles_) + omitted_cycles);
  end_write();
}

TaskStatsSnapshot TaskStats::snapshot() const {
  TaskStatsSnapshot out;
  RawExtremes exec;
  RawExtremes latency;
  for (unsigned attempt = 0;; ++attempt) {
    if (attempt >= 64) {
      // The writer was preempted inside its (short) write section: let it run.
      std::this_thread::yield();
    }
    const std::uint64_t before = seq_.load(std::memory_order_acquire);
    if ((before & 1U) != 0) {
      continue;
    }
    out.cycles = peek(cycles_);
    out.overruns = peek(overruns_);
    out.omitted_cycles = peek(omitted_cycles_);
    exec = {peek(exec_.min_ns), peek(exec_.max_ns), peek(exec_.sum_ns)};
    latency = {peek(latency_.min_ns), peek(latency_.max_ns), peek(latency_.sum_ns)};
    // Ordered after the acquire loads above: changed means a write overlapped them.
    if (seq_.load(std::memory_order_relaxed) == before) {
      break;
    }
  }
  out.exec = summarize(exec, out.cycles, exec_histogram_);
  out.latency = summarize(latency, out.cycles, latency_histogram_);
  return out;
}

void TaskStats::reset() noexcept {
  cycles_.store(0, std::memory_order_relaxed);
  overruns_.store(0, std::memory_order_relaxed);
  omitted_cycles_.store(0, std::memory_order_relaxed);
  for (Extremes* e : {&exec_, &latency_}) {
    e->min_ns.store(0, std::memory_order_relaxed);
    e->max_ns.store(0, std::memory_order_relaxed);
    e->sum_ns.store(0, std::memory_order_relaxed);
  }
  exec_histogram_.reset();
  latency_histogram_.reset();
  // Even and advanced: a snapshot started before the reset cannot validate against it.
  seq_.store((own(seq_) | 1U) + 1, std::memory_order_release);
}

}  // namespace edm::rt
