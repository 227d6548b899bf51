#pragma once
// The shared state of `edmhmi serve` (docs/web.md): the one bridge session to edmplc, what every
// browser is sent, and the workers that make blocking bridge requests.
//
//   link thread (web_hub_link.cpp): connects to edmplc — at start and after edmplc went away,
//   with back-off, never giving up — then machine.info, capabilities, chart variables,
//   subscriptions; meanwhile every socket, logged in or not, is told {"t":"bridge","up":false,
//   "message":"waiting for edmplc at H:P …"} and the page shows it.
//   bridge events (client I/O thread) ──▶ latest status, telemetry rows, alarm list  (mutex)
//   frame timer (server I/O thread, 25 Hz) ──▶ one batched "frame" to every logged-in browser
//   browser commands ──▶ worker threads (blocking bridge requests) ──▶ reply posted to the I/O
//   thread. Three lanes, so nothing slow stands before an E-stop: machine commands (E-stop,
//   hold, stop, jog, home, touch, …), program work (check, upload, MDI, run from a line,
//   variables, statistics) and log-ins (each checked by a hello of its own, after the
//   per-browser throttle, web_login.hpp).
//   the manual functions (WebManual, its own thread): a held jog refreshed, manual.status and
//   offset.get followed; their changes go out with the next frame.
//
// Telemetry: the bridge's trace stream (every cycle of the motion task) is thinned to one row per
// 20 ms of machine time and at most kMaxRowsPerFrame rows a frame, so a browser receives at most
// 25 frames and 100 rows a second whatever the machine's rate or clock speed.
//
// Thread-safety: attach/detach/watch/broadcast/frame building, login_throttle() and
// queued_bytes() on the I/O thread; the event handlers on the client's thread; post_work() and
// the PageBackend members from any thread (the blocking ones from a worker). Shared fields are
// under mutex_.

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
#include "edm/hmi/web_command.hpp"
#include "edm/hmi/web_job.hpp"
#include "edm/hmi/web_login.hpp"
#include "edm/hmi/web_manual.hpp"
#include "edm/hmi/web_shift.hpp"

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

class WebHub : public PageBackend {
 public:
  static constexpr int kFrameHz = 25;
  static constexpr std::size_t kMaxRowsPerFrame = 4;
  static constexpr double kRowPeriodS = 0.02;  // machine time between telemetry rows
  static constexpr std::size_t kMaxAlarms = 200;
  /// Rows sent lately, given to a browser that logs in (a reload keeps the charts' recent past).
  static constexpr std::size_t kHistoryRows = 1500;
  static constexpr std::size_t kWorkQueue = 64;
  /// Reconnection to edmplc: first wait, then doubling up to the longest.
  static constexpr std::chrono::milliseconds kReconnectFirst{250};
  static constexpr std::chrono::milliseconds kReconnectMax{5000};

  WebHub(boost::asio::io_context& ioc, bridge::Client& client, ConnectionSettings settings);
  ~WebHub() override;
  WebHub(const WebHub&) = delete;
  WebHub& operator=(const WebHub&) = delete;

  /// Starts the link thread (connects to edmplc, with back-off, for as long as the hub runs) and
  /// the frame timer. Never blocks, never throws for an edmplc that is not there.
  void start();
  /// Stops the link, the timer and the workers (joins them). Idempotent.
  void stop();
  /// edmplc is connected and the hub has its machine.info, series and subscriptions.
  [[nodiscard]] bool ready() const;
  /// {"t":"bridge","up","message"} now.
  [[nodiscard]] std::string bridge_message() const;

  /// A logged-in browser: frames and job broadcasts from now on.
  void attach(const std::shared_ptr<WebSink>& sink);
  void detach(const WebSink* sink);
  /// Any socket, logged in or not: the bridge's up/down messages from now on.
  void watch(const std::shared_ptr<WebSink>& sink);
  /// Sends `message` to every attached browser (I/O thread).
  void broadcast(const std::string& message);

  enum class Lane { kMachine, kProgram, kLogin };
  /// Runs `work` on the lane's worker thread; false (nothing queued) when kWorkQueue items wait.
  bool post_work(Lane lane, std::function<void()> work);
  boost::asio::io_context& io() { return ioc_; }

  /// Checks a browser's token with a hello of its own to edmplc, saying the browser's address
  /// (`peer`) in it. Blocking (worker thread). Returns the role edmplc gave, capped by the server
  /// session's own role; throws bridge::ClientError (code kUnauthorized: the token was refused;
  /// none: edmplc did not answer).
  bridge::Role authenticate(const std::string& token, const std::string& peer);
  LoginThrottle& login_throttle() { return throttle_; }
  /// Bytes queued to every browser (WebOutbox's shared total; I/O thread).
  std::size_t& queued_bytes() { return queued_bytes_; }

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
    std::uint64_t frames{0}, browsers{0}, frames_dropped{0}, slow_disconnects{0},
        reply_overflows{0}, login_failures{0}, bridge_connects{0};
  };
  [[nodiscard]] Counters counters() const;
  void count_drop();
  void count_slow_disconnect();
  void count_reply_overflow();
  void count_login_failure();

  // PageBackend (web_hub_backend.cpp): the commands of run_page_command().
  bridge::Json relay(std::string_view op, const bridge::Json& params) override;
  bridge::Json check(const std::string& text, const std::string& name) override;
  bridge::Json upload(const std::string& text, const std::string& name) override;
  bridge::Json start_job(bool dry_run) override;
  bridge::Json start_from(std::int32_t line, std::optional<double> depth_done_mm,
                          bool dry_run) override;
  bridge::Json mdi(const std::string& line) override;
  bridge::Json jog_hold(std::uint64_t owner, const std::string& axis,
                        double velocity_mm_s) override;
  void jog_stop_hold() override;
  void jog_release(std::uint64_t owner) override;
  bridge::Json touch(const std::string& target, const std::string& set_frame) override;
  bridge::Json offset_set(const bridge::Json& params) override;
  void acknowledge(std::uint64_t seq) override;
  bridge::Json manual_status() override;
  bridge::Json offsets() override;
  bridge::Json job_snapshot() override;
  bridge::Json stats() override;
  bridge::Json queue_add(const QueueItem& item) override;
  bridge::Json queue_control(std::string_view action) override;
  bridge::Json queue_snapshot() override;
  bridge::Json electrode_measure(const std::string& reference, const std::string& frame) override;
  bridge::Json condition_set(const bridge::Json& params) override;

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

  // The link to edmplc (web_hub_link.cpp).
  void link_loop();
  /// After a connect: machine.info, capabilities, offsets, series, subscriptions. Throws.
  void set_up_session();
  /// Sets the bridge state the page is told, and tells every socket when it changed.
  void set_bridge_state(bool up, std::string message);
  void broadcast_all(const std::string& message);

  boost::asio::io_context& ioc_;
  bridge::Client& client_;
  ConnectionSettings settings_;
  WebJob job_;
  WebManual manual_;
  WebShift shift_;  // the queue and the electrode measurement, on sessions of their own
  boost::asio::steady_timer timer_;
  std::vector<std::weak_ptr<WebSink>> sinks_;    // logged in; I/O thread only
  std::vector<std::weak_ptr<WebSink>> watched_;  // every socket; I/O thread only
  LoginThrottle throttle_;                       // I/O thread only
  std::size_t queued_bytes_{0};                  // I/O thread only

  mutable std::mutex mutex_;
  std::condition_variable link_cv_;
  std::thread link_thread_;
  bool link_stopping_{false};
  bool ready_{false};
  bool lost_{false};         // the client said the connection went away
  std::string bridge_text_;  // the current {"t":"bridge",…}
  bridge::Json caps_;
  std::vector<WebSeries> series_;
  bridge::Json last_status_;  // the latest status event's fields
  bool status_fresh_{false};
  bool bridge_up_{false};
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
