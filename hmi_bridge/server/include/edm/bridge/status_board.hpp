#pragma once
// The status snapshot the RT side publishes for the bridge (DESIGN §9: "lock-free queues /
// snapshots only"). Attached as a CycleObserver to the I/O task: at the end of each of its cycles
// it copies the machine state, the job progress and a few key pins into a seqlock the server's
// thread samples at each subscriber's rate.
//
// Seqlock: the writer bumps the version to odd, stores the snapshot's words with relaxed atomic
// stores, and bumps it to even; a reader retries while the version is odd or has moved. Every
// shared word is a std::atomic, so there is no data race (TSan-clean) and the writer never
// waits: a slow or stalled reader only retries, it cannot hold the RT thread.
//
// RT-safety: on_cycle_end() is RT-safe (no allocation, lock or syscall). read() is wait-free for
// the writer and lock-free for readers; any number of reader threads. Construct and attach
// before the tasks run.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/cycle_observer.hpp"
#include "edm/runtime/job.hpp"
#include "edm/runtime/machine.hpp"
#include "edm/runtime/pin.hpp"

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
  /// The latest snapshot; false when none has been published yet. Any thread.
  bool read(StatusSnapshot& out) const noexcept;

 private:
  static constexpr std::size_t kWords = (sizeof(StatusSnapshot) + 7) / 8;
  void publish(const StatusSnapshot& s) noexcept;

  const rt::Machine* machine_;
  const rt::JobStore* job_;
  std::array<rt::PinRef, kMaxStatusVars> pins_{};
  std::uint32_t n_pins_{0};
  std::uint64_t publications_{0};  // writer-side only
  std::atomic<std::uint64_t> version_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace edm::bridge
