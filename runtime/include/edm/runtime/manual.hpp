#pragma once
// ManualControl: the operator's manual motion requests (DESIGN §12, issue 21) — reference
// (homing), jog (continuous with a dead-man, incremental) and touch-off — on their way from the
// bridge to the block that moves the axes (programs::ManualMotion, a child of EdmJob), and that
// block's state and results on their way back.
//
//   bridge (non-RT)  request()  ──MpmcQueue<ManualRequest, 16>──▶  rt_poll()   ManualMotion (RT)
//   bridge (non-RT)  status()   ◀──Seqlock<ManualStatus>──────────  rt_publish()
//
// Every request carries a sequence number and is queued, in order: the RT side takes every
// request of a cycle, one after the other (a jog and a stop sent together both run), never only
// the newest. A full queue refuses the request (request() returns 0), so nothing is answered ok
// and then lost. What the manual motion is doing or is about to do — the newest request the RT
// side has not taken yet, else its published status — is activity(): the bridge judges a new
// request by it (docs/protocol.md "Op states"), so a touch sent in the same write as a jog is
// refused, not silently dropped. A continuous
// jog is kept alive by sending it again (any new request counts): the RT side stops the axis
// when it has seen no request for `deadman` (its own clock: the cycle release at which it saw
// the last one), so a client that dies, hangs or loses its network never keeps an axis moving.
//
// The referenced-axes mask and the position epoch (bumped when homing sets an axis's encoder)
// are read by the safety supervisor: soft limits apply to referenced axes only (an unreferenced
// axis's coordinates mean nothing yet, LinuxCNC does the same), and the following-error model
// restarts from the actual position when the epoch moves.
//
// Thread-safety: request() and activity() from any non-RT thread (serialised by a mutex the RT
// side never takes); rt_poll()/rt_publish()/set_referenced()/bump_position_epoch() from the one RT
// thread that runs ManualMotion; status(), info(), referenced(), position_epoch() from any thread.
// attach() at configure time only.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string_view>

#include "edm/runtime/mpmc_queue.hpp"
#include "edm/runtime/seqlock.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

enum class ManualOp : std::uint8_t { kNone, kHome, kJogDistance, kJogVelocity, kTouch, kStop };
enum class TouchTarget : std::uint8_t { kZ, kXPlus, kXMinus, kYPlus, kYMinus, kCenter };
enum class ManualMode : std::uint8_t { kIdle, kHome, kJog, kTouch };
enum class ManualError : std::uint8_t {
  kNone,
  kStopped,           // jog.stop, or the operator's request replaced it
  kDeadman,           // continuous jog: no refresh within the dead-man time
  kNoContact,         // touch: no contact within the search distance
  kAlreadyInContact,  // touch: the contact reads true before moving
  kSoftLimit,         // the move would leave the soft limits of a referenced axis
  kNoSwitch,          // home: the switch did not trip within the search distance
  kInterrupted,       // the machine left READY (E-stop, fault, a job started)
  kNotAvailable,      // this machine cannot (no switch / no contact input wired)
  kBadRequest,        // out of range (checked again on the RT side)
};

std::string_view to_string(ManualOp op) noexcept;
std::string_view to_string(TouchTarget t) noexcept;
std::string_view to_string(ManualMode m) noexcept;
std::string_view to_string(ManualError e) noexcept;
/// A stable machine-readable name: "", "stopped", "deadman", "no_contact", "in_contact",
/// "soft_limit", "no_switch", "interrupted", "not_available", "bad_request".
std::string_view error_code(ManualError e) noexcept;
/// "z", "x+", "x-", "y+", "y-", "center" → target; false when unknown.
bool touch_target_from_string(std::string_view s, TouchTarget& out) noexcept;

inline constexpr int kManualAxes = 3;  // X, Y, Z (bit 0, 1, 2 of the masks)

struct ManualRequest {
  std::uint64_t seq{0};
  ManualOp op{ManualOp::kNone};
  std::uint8_t axes{0};  // kHome: mask of the axes to reference (in the block's order)
  std::uint8_t axis{0};  // kJog*: 0 X, 1 Y, 2 Z
  TouchTarget target{TouchTarget::kZ};
  double value{0.0};  // kJogDistance: mm (signed); kJogVelocity: mm/s (signed)
};

/// The last finished manual operation.
struct ManualResult {
  std::uint64_t seq{0};  // the request it answers (0: none yet)
  ManualOp op{ManualOp::kNone};
  TouchTarget target{TouchTarget::kZ};
  bool ok{false};
  ManualError error{ManualError::kNone};
  double x{0.0}, y{0.0}, z{0.0};  // touch: the surface Z / edge X or Y / centre XY (machine)
  double size{0.0};               // touch center: the bore's diameter in X (mm); 0 otherwise
  double t_s{0.0};                // when it ended (the runtime's clock)
};

struct ManualStatus {
  ManualMode mode{ManualMode::kIdle};
  bool busy{false};
  ManualOp op{ManualOp::kNone};  // the operation running (kNone when idle)
  std::uint64_t seen_seq{0};     // the newest request the RT side has taken
  std::uint64_t refused_seq{0};  // the newest request it refused because another one ran
  ManualResult result{};
};

/// What the machine's manual-motion block offers (set once at configure time).
struct ManualInfo {
  bool available{false};           // a ManualMotion block runs on this machine
  bool home{false};                // reference switches wired
  bool touch{false};               // the contact input wired
  bool reference_required{false};  // programs refused until every axis is referenced
  double deadman_ms{500.0};
  double jog_v_max_mm_s{5.0};
  double jog_distance_min_mm{0.001};
  double jog_distance_max_mm{10.0};
  double electrode_d_mm{1.0};
};

class ManualControl {
 public:
  ManualControl() = default;
  ManualControl(const ManualControl&) = delete;
  ManualControl& operator=(const ManualControl&) = delete;

  /// Configure time (non-RT): the block says what it offers and which axes start referenced.
  void attach(const ManualInfo& info, std::uint8_t referenced_at_start) noexcept;
  [[nodiscard]] ManualInfo info() const noexcept;

  /// Requests queued and not yet taken by the RT side, at most.
  static constexpr std::size_t kQueueCapacity = 16;

  /// Non-RT, any thread. Queues `r` (its seq is assigned here) and returns the seq; 0 when the
  /// queue is full (the RT side is not taking requests: refuse the operator's request).
  std::uint64_t request(ManualRequest r) noexcept;

  /// The manual operation running or about to run, as a new request must be judged: the op of
  /// the newest request the RT side has not taken yet, else status().op. A pending kStop counts
  /// as idle (kNone): the queue is ordered, so what is sent after a stop runs after it.
  /// Non-RT, any thread.
  [[nodiscard]] ManualOp activity() const noexcept;

  /// RT: the oldest queued request newer than `last_seq` (updated); false when none is queued.
  bool rt_poll(ManualRequest& out, std::uint64_t& last_seq) noexcept;
  /// RT: publishes the block's state.
  void rt_publish(const ManualStatus& s) noexcept { status_.store(s); }
  /// Any thread.
  [[nodiscard]] ManualStatus status() const noexcept { return status_.load(); }

  /// Mask of referenced axes (bit 0 X, 1 Y, 2 Z). Any thread.
  [[nodiscard]] std::uint8_t referenced() const noexcept {
    return referenced_.load(std::memory_order_acquire);
  }
  [[nodiscard]] bool all_referenced() const noexcept { return referenced() == 0x7; }
  /// True when programs may run: referencing is not required, or every axis is referenced.
  [[nodiscard]] bool may_run_programs() const noexcept {
    return !reference_required_.load(std::memory_order_acquire) || all_referenced();
  }
  /// RT: axis `axis` is referenced (its encoder was set at its switch).
  void set_referenced(int axis) noexcept {
    referenced_.fetch_or(static_cast<std::uint8_t>(1U << axis), std::memory_order_acq_rel);
  }
  /// Increments whenever an axis's encoder is set (the readings jump). Any thread.
  [[nodiscard]] std::uint64_t position_epoch() const noexcept {
    return position_epoch_.load(std::memory_order_acquire);
  }
  /// RT.
  void bump_position_epoch() noexcept { position_epoch_.fetch_add(1, std::memory_order_acq_rel); }

 private:
  mutable std::mutex writer_;  // serialises request() and activity(); never taken by the RT side
  std::uint64_t next_seq_{0};
  ManualOp newest_op_{ManualOp::kNone};  // the op of request next_seq_ (guarded by writer_)
  MpmcQueue<ManualRequest, kQueueCapacity> queue_;
  Seqlock<ManualStatus> status_;
  Seqlock<ManualInfo> info_;
  std::atomic<std::uint8_t> referenced_{0x7};
  std::atomic<bool> reference_required_{false};
  std::atomic<std::uint64_t> position_epoch_{0};
};

}  // namespace edm::rt
