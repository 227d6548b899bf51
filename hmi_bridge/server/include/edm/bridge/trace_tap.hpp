#pragma once
// The bridge's trace tap: a second consumer of per-cycle samples, independent of the CSV trace
// recorder (trace.hpp), so streaming a trace to an HMI never steals samples from --trace-out.
//
// One tap per task, attached as a CycleObserver. It owns its own SPSC ring (producer: the task's
// RT thread; consumer: the bridge server's thread) and its own rt::PinSampler (the recorder's
// sampler type), whose pins trace.start / trace.stop set. The RT side never waits: a full ring
// drops the sample and counts it.
//
// Reconfiguring while the task runs (Dekker-style handshake, seq_cst): the RT side raises
// `busy_`, then checks `armed_`; configure() lowers `armed_` and then waits — on the non-RT
// side only — until `busy_` is down, so the RT thread is never inside the old pin list when it
// is replaced.
//
// Thread-safety: on_cycle_end() from the owning task's thread only (RT-safe). configure(),
// drain() and dropped() from one non-RT consumer thread (the server's).

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/cycle_observer.hpp"
#include "edm/runtime/pin.hpp"
#include "edm/runtime/pin_sampler.hpp"

namespace edm::bridge {

class TraceTap final : public rt::CycleObserver {
 public:
  static constexpr std::size_t kCapacity = 4096;  // samples (4 s at 1 kHz)

  explicit TraceTap(std::string task_name);

  /// RT-safe. Samples the armed pins into the ring.
  void on_cycle_end(const rt::CycleContext& ctx) noexcept override;

  /// Non-RT. Replaces the sampled pins (empty: off) and empties the ring. At most
  /// rt::kMaxTraceVarsPerTask pins, none null (std::invalid_argument otherwise, and the tap
  /// keeps its pins and its queued samples).
  void configure(const std::vector<rt::PinRef>& pins);
  /// Non-RT. Moves up to `max` queued samples to out (appended). Returns how many.
  std::size_t drain(std::vector<rt::TraceSample>& out, std::size_t max);
  [[nodiscard]] std::uint64_t dropped() const noexcept {
    return dropped_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] const std::string& task_name() const noexcept { return task_name_; }
  [[nodiscard]] std::uint32_t pin_count() const noexcept { return sampler_.size(); }

 private:
  std::string task_name_;
  rt::PinSampler sampler_;
  std::atomic<bool> armed_{false};
  std::atomic<bool> busy_{false};
  std::atomic<std::uint64_t> dropped_{0};
  boost::lockfree::spsc_queue<rt::TraceSample, boost::lockfree::capacity<kCapacity>> ring_;
};

}  // namespace edm::bridge
