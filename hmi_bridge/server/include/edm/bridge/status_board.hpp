#pragma once
// The status snapshot the RT side publishes for the bridge (DESIGN §9: "lock-free queues /
// snapshots only"). Attached as a CycleObserver to the I/O task: at the end of each of its cycles
// it copies the machine state, the job progress and a few key pins into a seqlock the server's
// thread samples at each subscriber's rate.
//
// The snapshot lives in the runtime's one seqlock, rt::Seqlock<StatusSnapshot> (seqlock.hpp says
// why its orderings are right): the writer never waits, a slow or stalled reader only retries.
//
// RT-safety: on_cycle_end() is RT-safe (no allocation, lock or syscall; the snapshot is built on
// the stack). read() is for non-RT threads (it retries, then yields, while a store overlaps); any
// number of reader threads. Construct and attach before the tasks run.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/cycle_observer.hpp"
#include "edm/runtime/job.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/pin.hpp"
#include "edm/runtime/seqlock.hpp"

namespace edm::bridge {

inline constexpr std::size_t kMaxStatusVars = 16;

struct StatusSnapshot {
  std::uint64_t publication{0};  // 1, 2, ... (0 = never published)
  rt::TimePoint release{0};
  std::uint64_t cycle{0};
  rt::MachineState state{rt::MachineState::kOff};
  rt::AlarmCode cause{rt::AlarmCode::kNone};
  rt::JobProgress job{};
  std::uint32_t n_vars{0};
  std::array<double, kMaxStatusVars> vars{};
};

class StatusBoard final : public rt::CycleObserver {
 public:
  /// pins: the key variables, at most kMaxStatusVars (throws std::invalid_argument otherwise).
  StatusBoard(const rt::Machine& machine, const rt::JobStore& job, std::vector<rt::PinRef> pins);

  /// RT-safe. Publishes one snapshot.
  void on_cycle_end(const rt::CycleContext& ctx) noexcept override;
  /// Publishes from a non-RT thread (used only while no task runs, e.g. tests). Not concurrent
  /// with on_cycle_end().
  void publish_now(rt::TimePoint release, std::uint64_t cycle) noexcept;
  /// The latest snapshot; false (out untouched) when none has been published yet. Any non-RT
  /// thread.
  bool read(StatusSnapshot& out) const noexcept;

 private:
  const rt::Machine* machine_;
  const rt::JobStore* job_;
  std::array<rt::PinRef, kMaxStatusVars> pins_{};
  std::uint32_t n_pins_{0};
  std::uint64_t publications_{0};      // writer-side only
  rt::Seqlock<StatusSnapshot> board_;  // publication 0 until the first publish
};

}  // namespace edm::bridge
