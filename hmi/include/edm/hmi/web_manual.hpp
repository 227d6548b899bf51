#pragma once
// The operator's manual functions as `edmhmi serve` runs them for the page (docs/web.md
// "Operator functions"): the continuous jog a browser holds, the touch whose result goes into a
// work offset, and manual.status / offset.get followed for every browser.
//
// Continuous jog. The runtime stops a velocity jog that is not refreshed within its dead-man
// (machine.info manual.deadman_ms, machine time). The *server* refreshes it, never the browser:
//   browser ── jog.hold ──▶ hub: the first `jog {axis, velocity}`; the reply says held_ms
//   browser ── held (every held_ms while the button is down) ──▶ hub: the hold stays alive
//   hub (its own thread) ── jog {axis, velocity} every refresh_ms ──▶ edmplc
//   no held for hold_window_ms, jog.release, or the browser's WebSocket closed ──▶ jog.stop
// so a browser that sleeps, loses its network or closes stops the axis within
// hold_window + refresh < the dead-man (on a real clock), and if `edmhmi serve` itself dies the
// runtime's own dead-man stops it. One hold at a time (the machine jogs one axis): a new hold,
// from any operator, replaces the last one.
//
// Machine time and real time: the dead-man counts machine time; on a paced virtual clock (tests,
// `./edm demo --fast`) that runs `clock_rate` times faster than the wall clock. The hub measures
// the rate from the status events' t_s, and every period here is real time: deadman_ms / rate.
//
// Touch with "set": the touch result (manual.status, once the runtime answers that request) goes
// into the chosen work frame by offset.set (manual.hpp offset_set_for_touch), done here so a
// browser that closes meanwhile changes nothing.
//
// Non-RT. Thread-safety: every public member may be called from any thread (one mutex); hold(),
// touch() and request_offset_set() block on bridge requests (call them from a worker thread);
// held(), release(), drop() and on_status_time() never block. The follower thread makes its own
// bridge requests.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "edm/bridge/client.hpp"

namespace edm::hmi {

/// The real-time periods of a held jog (all in ms). Pure.
struct JogTiming {
  double deadman_ms{0.0};      // the runtime's dead-man in real time: deadman / clock rate
  double refresh_ms{0.0};      // the hub re-sends the jog this often: deadman/3, ≥ 5 ms
  double hold_window_ms{0.0};  // no "held" for this long: jog.stop — deadman/2, ≥ kMinHoldWindowMs
  double held_ms{0.0};         // the browser says "held" this often: hold_window/3
};
/// A browser's timers are not finer than this (background tabs: far coarser, which stops a jog).
inline constexpr double kMinHoldWindowMs = 150.0;
[[nodiscard]] JogTiming jog_timing(double deadman_ms, double clock_rate) noexcept;

/// A bridge reply as the page's reply: {"ok": true, "body"} or {"ok": false, "code", "message",
/// "details"?} (code "transport" when edmplc did not answer).
bridge::Json page_reply(const bridge::Reply& r);

class WebManual {
 public:
  explicit WebManual(bridge::Client& client) : client_(client) {}
  ~WebManual();
  WebManual(const WebManual&) = delete;
  WebManual& operator=(const WebManual&) = delete;

  /// From machine.info: the dead-man (manual.deadman_ms) and whether manual.status and
  /// offset.get exist; the first call starts the follower thread, a later one (edmplc again,
  /// after a restart) updates them.
  void start(const bridge::Json& manual_info, bool has_manual_status, bool has_offsets);
  void stop();  // joins the thread; a held jog is stopped first. Idempotent.

  /// Status events' machine time (s), for the clock rate.
  void on_status_time(double t_s);
  [[nodiscard]] double clock_rate() const;
  [[nodiscard]] JogTiming timing() const;

  /// Starts a continuous jog for `owner` (a browser session id): sends the first jog and, when
  /// edmplc accepts it, keeps it alive while held() comes. Blocking. The page's reply
  /// ({"ok", "body": {"seq", "deadman_ms", "held_ms"}} or the refusal).
  bridge::Json hold(std::uint64_t owner, const std::string& axis, double velocity_mm_s);
  /// The browser still holds the button.
  void held(std::uint64_t owner);
  /// The browser let go (or its socket closed: drop): jog.stop at once, from the follower.
  void release(std::uint64_t owner);
  void drop(std::uint64_t owner) { release(owner); }
  /// jog.stop from any operator ends the hold, whoever holds it (the runtime stops the jog, and
  /// a refresh must not start it again).
  void release_any();

  /// touch {target}; with `set_frame` ("G54".."G59", or empty) the result goes into that frame.
  /// Blocking; the page's reply.
  bridge::Json touch(const std::string& target, const std::string& set_frame);
  /// offset.set, then the offsets are read again and sent to every browser. Blocking.
  bridge::Json offset_set(const bridge::Json& params);

  /// {"mode", "busy", "referenced", "result", …} of the last manual.status, plus "touch_set"
  /// (the last touch-into-offset: {"frame", "ok", "message", "x"?, "y"?, "z"?}) and "jog"
  /// ({"held": bool, "axis", "velocity", "error"?}); null before the first.
  [[nodiscard]] bridge::Json manual_json() const;
  /// offset.get's {"frames", "generation"}, null when edmplc has none.
  [[nodiscard]] bridge::Json offsets_json() const;
  /// What changed since the last call (the hub's frame timer): each is null when unchanged.
  struct Changes {
    bridge::Json manual, offsets;
  };
  Changes take_changes();

 private:
  void run();
  void follow_status();
  void follow_offsets();

  struct Hold {
    std::uint64_t owner{0};
    std::string axis;
    double velocity_mm_s{0.0};
    std::chrono::steady_clock::time_point last_held, next_refresh;
  };
  struct PendingTouch {
    std::uint64_t seq{0};
    std::string target, frame;
  };

  bridge::Client& client_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::thread thread_;
  bool stopping_{false};
  bool started_{false};
  bool has_status_{false}, has_offsets_{false};
  double deadman_ms_{500.0};
  // Clock rate: machine seconds per real second, from two status times far enough apart.
  double rate_{1.0};
  std::optional<std::pair<double, std::chrono::steady_clock::time_point>> rate_ref_;
  std::optional<Hold> hold_;
  bool stop_jog_{false};                       // jog.stop to send (release, expiry)
  std::optional<std::uint64_t> pending_hold_;  // a hold() in flight for this owner
  bool pending_released_{false};               // … and released meanwhile
  std::optional<PendingTouch> touch_;
  bool offsets_stale_{true};
  bridge::Json manual_ = nullptr, offsets_ = nullptr;
  bridge::Json touch_set_ = nullptr, jog_error_ = nullptr;
  bool manual_changed_{false}, offsets_changed_{false};
  std::chrono::steady_clock::time_point next_status_{}, next_offsets_{};
};

}  // namespace edm::hmi
