#pragma once
// The shared state of `edmhmi serve` (docs/web.md): the one bridge session to edmplc, what every
// browser is sent, and the worker that makes blocking bridge requests.
//
//   bridge events (client I/O thread) ──▶ latest status, telemetry rows, alarm list  (mutex)
//   frame timer (server I/O thread, 25 Hz) ──▶ one batched "frame" to every attached browser
//   browser commands ──▶ worker threads (blocking bridge requests) ──▶ reply posted to the I/O
//   thread. Three lanes, so nothing slow stands before an E-stop: machine commands (E-stop,
//   hold, stop, jog, home, touch, …), program work (check, upload, MDI, run from a line,
//   variables, statistics) and log-ins (a wrong token is answered late by edmplc's hello
//   throttle).
//   the manual functions (WebManual, its own thread): a held jog refreshed, manual.status and
//   offset.get followed; their changes go out with the next frame.
//
// Telemetry: the bridge's trace stream (every cycle of the motion task) is thinned to one row per
// 20 ms of machine time and at most kMaxRowsPerFrame rows a frame, so a browser receives at most
// 25 frames and 100 rows a second whatever the machine's rate or clock speed.
//
// Thread-safety: attach/detach/broadcast/frame building run on the I/O thread; the event handlers
// on the client's thread; post_work() from any thread. Shared fields are under mutex_.

#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/connection.hpp"
#include "edm/hmi/web_job.hpp"
#include "edm/hmi/web_manual.hpp"

namespace edm::hmi {

/// A browser as the hub sees it. send() is called on the I/O thread only.
class WebSink {
 public:
  virtual ~WebSink() = default;
  virtual void send(std::shared_ptr<const std::string> message) = 0;
};

/// A chart series: the page's key and the variable that feeds it on this machine.
struct WebSeries {
  std::string key;
  std::string var;
};

class WebHub {
 public:
  static constexpr int kFrameHz = 25;
  static constexpr std::size_t kMaxRowsPerFrame = 4;
  static constexpr double kRowPeriodS = 0.02;  // machine time between telemetry rows
  static constexpr std::size_t kMaxAlarms = 200;
  /// Rows sent lately, given to a browser that logs in (a reload keeps the charts' recent past).
  static constexpr std::size_t kHistoryRows = 1500;
  static constexpr std::size_t kWorkQueue = 64;

  WebHub(boost::asio::io_context& ioc, bridge::Client& client, ConnectionSettings settings);
  ~WebHub();
  WebHub(const WebHub&) = delete;
  WebHub& operator=(const WebHub&) = delete;

  /// After the client connected: machine.info, capabilities, chart variables, subscriptions,
  /// the frame timer. Blocking: call before running the I/O thread. Throws bridge::ClientError.
  void start();
  /// Stops the timer and the worker (joins it). Idempotent.
  void stop();

  void attach(const std::shared_ptr<WebSink>& sink);
  void detach(const WebSink* sink);
  /// Sends `message` to every attached browser (I/O thread).
  void broadcast(const std::string& message);

  enum class Lane { kMachine, kProgram, kLogin };
  /// Runs `work` on the lane's worker thread; false (nothing queued) when kWorkQueue items wait.
  bool post_work(Lane lane, std::function<void()> work);
  boost::asio::io_context& io() { return ioc_; }

  /// Checks a browser's token with a hello of its own to edmplc. Blocking (worker thread).
  /// Returns the role edmplc gave, capped by the server session's own role; throws
  /// bridge::ClientError when the token is refused.
  bridge::Role authenticate(const std::string& token);

  /// The "welcome" message of a logged-in browser: role, machine, capabilities, series, the job,
  /// the alarm list, the last status, manual.status and the work offsets.
  [[nodiscard]] std::string welcome(bridge::Role role) const;
  /// Marks the alarms up to `seq` acknowledged and sends the list to everyone (I/O thread).
  void acknowledge_alarms(std::uint64_t seq);
  /// Sends the job snapshot to everyone (after an upload or start).
  void broadcast_job();

  bridge::Client& client() { return client_; }
  WebJob& job() { return job_; }
  WebManual& manual() { return manual_; }

  struct Counters {
    std::uint64_t frames{0}, browsers{0}, frames_dropped{0}, slow_disconnects{0};
  };
  [[nodiscard]] Counters counters() const;
  void count_drop();
  void count_slow_disconnect();

  /// Expires when the hub is destroyed: a session outliving it (destroyed with the io_context's
  /// pending handlers after the hub, at shutdown) must not call back into it.
  [[nodiscard]] std::weak_ptr<const bool> alive_token() const noexcept { return alive_; }

 private:
  std::shared_ptr<const bool> alive_ = std::make_shared<const bool>(true);
  void on_event(const bridge::Json& ev);
  void on_trace(const bridge::Json& ev);
  void arm_timer();
  void on_timer();
  struct Worker {
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<std::function<void()>> queue;
    bool stopping{false};
    std::thread thread;
  };
  void worker_loop(Worker& w);
  [[nodiscard]] bridge::Json alarms_json_locked() const;

  boost::asio::io_context& ioc_;
  bridge::Client& client_;
  ConnectionSettings settings_;
  WebJob job_;
  WebManual manual_;
  boost::asio::steady_timer timer_;
  std::vector<std::weak_ptr<WebSink>> sinks_;  // I/O thread only

  mutable std::mutex mutex_;
  bridge::Json caps_;
  std::vector<WebSeries> series_;
  bridge::Json last_status_;  // the latest status event's fields
  bool status_fresh_{false};
  bool bridge_up_{true};
  bool bridge_changed_{false};
  std::vector<double> row_;  // latest value per series (NaN: none yet)
  double last_row_t_{-1.0};
  std::vector<bridge::Json> rows_;    // pending for the next frame
  std::deque<bridge::Json> history_;  // the last kHistoryRows rows sent
  std::deque<bridge::Json> alarms_;
  std::vector<bridge::Json> new_alarms_;
  std::uint64_t alarm_seq_{0};
  Counters counters_;

  std::array<Worker, 3> workers_;
  bool stopped_{false};
};

}  // namespace edm::hmi
