#pragma once
// Internals of the bridge server: the shared state (Server::Impl) and the Session.
// Everything here runs on the server's single io thread (one thread runs the io_context, so
// handlers never run concurrently). Counters are atomics so stats() may be read from any thread.

#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "audit.hpp"
#include "condition_edits.hpp"
#include "edm/bridge/codec.hpp"
#include "edm/bridge/hello_throttle.hpp"
#include "edm/bridge/server.hpp"
#include "edm/bridge/status_board.hpp"
#include "edm/bridge/trace_tap.hpp"
#include "edm/bridge/transport.hpp"
#include "edm/machining/wear_precomp.hpp"
#include "edm/runtime/log_escape.hpp"
#include "edm/runtime/log_limiter.hpp"
#include "edm/runtime/runtime.hpp"
#include "electrode_table.hpp"
#include "job_log.hpp"

namespace boost::asio::ssl {
class context;
}

namespace edm::bridge {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using SteadyClock = std::chrono::steady_clock;

class Session;

struct Counters {
  std::atomic<std::uint64_t> sessions_open{0};
  std::atomic<std::uint64_t> sessions_pending{0};
  std::atomic<std::uint64_t> sessions_accepted{0};
  std::atomic<std::uint64_t> sessions_refused{0};
  std::atomic<std::uint64_t> pending_evicted{0};
  std::atomic<std::uint64_t> hello_timeouts{0};
  std::atomic<std::uint64_t> hello_failures{0};
  std::atomic<std::uint64_t> accept_errors{0};
  std::atomic<std::uint64_t> queue_bytes_peak{0};
  std::atomic<std::uint64_t> requests{0};
  std::atomic<std::uint64_t> errors{0};
  std::atomic<std::uint64_t> events_sent{0};
  std::atomic<std::uint64_t> events_dropped{0};
  std::atomic<std::uint64_t> slow_disconnects{0};
  std::atomic<std::uint64_t> timeouts{0};
  std::atomic<std::uint64_t> programs_committed{0};
};

/// A reply to send, or nothing (the request produced no reply), plus what to do after it.
struct OpResult {
  Json reply;
  bool close_after{false};
  /// The hello may not be evaluated yet (failed-hello throttle): run it again at this time.
  std::optional<SteadyClock::time_point> retry_at;
};

/// Longest line a session that has not said hello yet may send (a hello is small).
inline constexpr std::size_t kPreAuthLineBytes = 8 * 1024;
/// Viewers may hold every session slot but this many: an operator always gets in.
inline constexpr int kOperatorReserve = 1;

struct Server::Impl {
  Impl(rt::Runtime& runtime, ServerOptions options);

  void start();
  void stop();
  void do_accept();
  void on_accept_error(const boost::system::error_code& ec);
  /// Registers a connected transport as a new pending session and starts it (io thread).
  void adopt(std::unique_ptr<Transport> t);
  /// A session said a valid hello as `role`: moves it to the authenticated sessions, or
  /// returns false (busy) when that role has no free slot.
  bool admit(Session& s, Role role);
  void on_alarm(const rt::Alarm& a);
  void progress_tick();
  void trace_tick();
  void remove(Session& s);
  /// Authenticated sessions, as strong references: broadcasts iterate this copy, because a
  /// send may close a session and closing removes it from the registry.
  std::vector<std::shared_ptr<Session>> live_sessions() const;
  /// Recomputes each task's tap from the union of the sessions' trace variables.
  void retrace();
  /// Fills a status message (from the board when it has published, else directly).
  StatusMessage status_message();
  /// status's job.last: the interrupted job (until one begins) or the last, aborted one.
  std::optional<LastJob> last_job();
  [[nodiscard]] ServerStats stats_snapshot() const noexcept;

  rt::Runtime& rt;
  /// Per job slot (main, MDI): the work-offset generation the committed program was interpreted
  /// with (program.begin's offsets_generation), checked again at cycle.start.
  std::array<std::optional<std::uint64_t>, 2> committed_offsets;
  /// Per job slot: the electrode wear the committed program is planned with, hole by hole
  /// (machining::planned_wear), checked against the electrode left at cycle.start.
  std::array<std::vector<machining::HoleWear>, 2> committed_wear;
  ServerOptions opt;
  TokenSet tokens;
  std::shared_ptr<asio::ssl::context> tls;  // null: plain TCP
  HelloThrottle throttle;
  /// Log lines a client's requests cause, per transport address: 20 at once, then 1 a second;
  /// the rest are counted and summed up (Session::log, the audit's log copy).
  rt::LogRateLimiter log_limiter;
  AuditLog audit;
  std::vector<std::string> status_var_names;
  /// The job block's name ("cnc.job"): the one output pin `<block>.job_time_s` of the config
  /// (the first, if several); empty when the config has none (its jobs are logged without
  /// figures).
  std::string job_block;
  std::unique_ptr<StatusBoard> board;
  std::vector<std::unique_ptr<TraceTap>> taps;      // one per task, same order as rt.tasks()
  std::vector<std::vector<std::string>> tap_names;  // the variables each tap samples, in order
  /// The alarm listener outlives the server inside the runtime: it reaches the server only
  /// through this, which stop() clears.
  struct AlarmLink {
    std::mutex mutex;
    Impl* target{nullptr};
  };
  std::shared_ptr<AlarmLink> alarm_link{std::make_shared<AlarmLink>()};
  /// The alarms raised since the start, newest last, capped (alarms.get). Server thread only.
  static constexpr std::size_t kAlarmHistory = 500;
  std::deque<Json> alarm_history;
  std::uint64_t alarms_forgotten{0};  // dropped from the history's front by the cap
  /// The job log (server_jobs.cpp): each job that ended, beside the retain file.
  static constexpr std::size_t kJobLogCap = 1000;
  std::unique_ptr<JobLog> job_log;
  struct JobWatch {
    std::uint64_t started{0};  // JobProgress::jobs_started last seen
    bool active{false};        // a job began and its entry is not written yet
    int settle_ticks{-1};      // ticks left before an ended job is logged (its alarms arrive)
    JobLogEntry entry;         // filled as the job runs
    rt::JobProgress end;       // the progress when it ended
    std::string recent;        // alarms since the last tick (a job that began within it has them)
    double drilled_mm{0.0};    // job_drilled_mm when it ended
  } job_watch;
  /// The job's figures when its end is seen, from job_block's outputs (server_jobs.cpp).
  void take_figures();
  /// The electrode table (ops_electrode.cpp), beside the retain file.
  std::unique_ptr<ElectrodeTable> electrodes;
  /// The operators' condition edits (condition.set), beside the retain file.
  std::unique_ptr<ConditionEdits> condition_edits;
  /// electrode.measure's touch, until its result is in: the length is the Z at contact − datum.
  struct PendingMeasure {
    std::uint64_t seq{0};
    std::string reference;  // setter, work
    double datum_mm{0.0};
  };
  std::optional<PendingMeasure> measuring;
  Json last_measure;  // null until a measurement ended
  /// Once per progress tick: applies a measurement whose touch ended (ops_electrode.cpp).
  void watch_measure();
  /// Once per progress tick: notes a job's start and end and logs it (server_jobs.cpp).
  void watch_jobs(const rt::JobProgress& p);
  /// The end of the job watched, if it ended since the last tick: its figures taken now. Also
  /// just before a program.commit and a cycle.start (a queue loads and starts the next job
  /// within a tick of the last one's end; the load resets the progress, the start the figures).
  void note_job_end(const rt::JobProgress& p);
  void log_job();
  std::uint16_t bound_port{0};
  std::uint64_t next_session_id{1};

  asio::io_context ioc{1};
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work;
  tcp::acceptor acceptor{ioc};
  asio::steady_timer accept_timer{ioc};
  std::chrono::milliseconds accept_backoff{0};
  asio::steady_timer progress_timer{ioc};
  asio::steady_timer trace_timer{ioc};
  rt::JobProgress last_progress{};
  SteadyClock::time_point next_log_sweep{};
  // Keyed by session id, so iteration is in age order (oldest first).
  std::map<std::uint64_t, std::weak_ptr<Session>> pending;   // no valid hello yet
  std::map<std::uint64_t, std::weak_ptr<Session>> sessions;  // authenticated
  std::thread thread;
  std::atomic<bool> started{false};
  std::atomic<bool> stopping{false};
  Counters counters;
  std::vector<rt::TraceSample> trace_scratch;
};

/// Program upload state of one session (program.begin/chunk/commit).
struct Upload {
  std::uint64_t id{0};
  std::size_t expected{0};
  rt::JobSlot slot{rt::JobSlot::kMain};  // program.begin's "slot": the part program or MDI
  std::optional<std::uint64_t> offsets_generation;  // the work offsets it was interpreted with
  std::vector<machining::MotionBlock> blocks;
  Crc32 crc;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(Server::Impl& server, std::unique_ptr<Transport> transport, std::uint64_t id);

  /// Handshake (TLS), then reads; the hello deadline starts now.
  void start();
  /// Closes the transport and cancels the timers; the session goes away when its handlers
  /// finish. Never call it while iterating the server's registries (use live_sessions()).
  void close();
  /// close() posted to the io thread (from anywhere, e.g. inside a broadcast loop).
  void async_close();
  /// Closes once the queued messages are written.
  void close_after_flush();
  /// Sends a reply. Never dropped: a client that does not read its replies stops being read
  /// (its requests wait in its own socket buffer) while the queue is over its byte limit.
  void send_reply(const Json& reply);
  /// Queues an event if the queue has room (messages and bytes); else drops it (counted) and
  /// disconnects a reader that stays stalled past stall_timeout. Assigns seq only to events
  /// actually queued, so a subscriber sees seq without gaps (`dropped` says what it missed).
  void send_event(std::string_view name, Json body);

  [[nodiscard]] bool wants(std::string_view topic) const;
  [[nodiscard]] const std::vector<std::string>& trace_vars() const { return trace_vars_; }
  [[nodiscard]] std::uint64_t id() const { return id_; }
  [[nodiscard]] const std::string& peer() const { return peer_; }
  [[nodiscard]] const std::string& peer_address() const { return address_; }
  [[nodiscard]] bool authenticated() const { return role_.has_value(); }
  [[nodiscard]] std::size_t queued_bytes() const { return queued_bytes_; }
  /// "session N (address:port via "peer")": how the log names this session. The peer (hello's
  /// relayed end client) is escaped.
  [[nodiscard]] std::string log_name() const;
  /// One log line about this session, "bridge: <log_name>: <message>", rate-limited per
  /// transport address (the lines beyond are counted and reported with the next one). Every
  /// client-supplied text in `args` must be escaped by the caller (rt::log_quoted).
  template <class... Args>
  void log(spdlog::level::level_enum level, fmt::format_string<Args...> format, Args&&... args) {
    std::uint64_t suppressed = 0;
    if (!spdlog::should_log(level) ||
        !server_.log_limiter.admit(address_, SteadyClock::now(), suppressed)) {
      return;
    }
    spdlog::log(level, "bridge: {}: {}{}", log_name(),
                fmt::format(format, std::forward<Args>(args)...), rt::suppressed_note(suppressed));
  }

 private:
  void on_handshake(boost::system::error_code ec);
  void do_read();
  void on_read(boost::system::error_code ec, std::size_t n);
  void process_input();
  void handle_line(std::string_view line);
  void arm_read_timer();
  void arm_hello_timer();
  void linger_close();
  void start_shutdown();
  void enqueue(std::string msg);
  [[nodiscard]] bool queue_full() const;
  void do_write();
  void on_write(boost::system::error_code ec, std::size_t n);
  void start_status_timer();
  void on_status_tick(boost::system::error_code ec, std::uint64_t gen);

  Server::Impl& server_;
  std::unique_ptr<Transport> transport_;
  const std::uint64_t id_;
  bool loopback_{false};
  std::string address_;
  std::string peer_;

  std::array<char, 64 * 1024> rx_{};
  std::string input_;  // the part of the last read not yet framed (while the queue is full)
  std::string line_;
  bool discarding_{false};  // skipping the rest of a too-long line
  bool reading_{false};
  bool read_paused_{false};
  bool handshaken_{false};
  asio::steady_timer read_timer_;
  asio::steady_timer hello_timer_;
  asio::steady_timer throttle_timer_;
  std::optional<std::string> deferred_hello_;  // waiting for the failed-hello throttle

  std::deque<std::string> queue_;
  std::size_t queued_bytes_{0};
  bool writing_{false};
  bool close_after_flush_{false};
  bool lingering_{false};
  bool close_posted_{false};  // a stalled session's close is posted (send_event)
  bool closed_{false};
  std::uint64_t seq_{0};
  std::uint64_t dropped_{0};
  std::optional<SteadyClock::time_point> stalled_since_;
  std::uint64_t status_gen_{0};

  std::optional<Role> role_;
  std::string via_;  // hello's "peer" (validated, printable ASCII), "" when none
  bool sub_status_{false};
  bool sub_alarm_{false};
  bool sub_progress_{false};
  int rate_hz_{0};  // kept after an unsubscribe: the next subscribe's default
  SteadyClock::time_point next_status_{};
  asio::steady_timer status_timer_;
  std::optional<Upload> upload_;
  std::vector<std::string> trace_vars_;

 public:  // what the ops (op_table.cpp, ops*.cpp) read and change
  struct Subscriptions {
    bool status{false};
    bool alarm{false};
    bool progress{false};
    int rate_hz{0};  // the status rate; 0 before the first status subscription
  };

  [[nodiscard]] Server::Impl& server() { return server_; }
  [[nodiscard]] bool loopback() const { return loopback_; }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
  [[nodiscard]] std::optional<Role> role() const { return role_; }
  /// A valid hello: the session is `r` from now on.
  void set_role(Role r) { role_ = r; }
  /// hello's "peer" (validated), "" when none.
  [[nodiscard]] const std::string& via() const { return via_; }
  void set_via(std::string via) { via_ = std::move(via); }
  [[nodiscard]] Subscriptions subscriptions() const {
    return {sub_status_, sub_alarm_, sub_progress_, rate_hz_};
  }
  /// Adds the topics given true; `status` (re)starts the status events at `rate_hz`.
  void subscribe(bool status, bool alarm, bool progress, int rate_hz) {
    sub_alarm_ = sub_alarm_ || alarm;
    sub_progress_ = sub_progress_ || progress;
    if (status) {
      sub_status_ = true;
      rate_hz_ = rate_hz;
      start_status_timer();
    }
  }
  /// Drops the topics given true; dropping status stops its events.
  void unsubscribe(bool status, bool alarm, bool progress) {
    if (status) {
      sub_status_ = false;
      start_status_timer();
    }
    sub_alarm_ = sub_alarm_ && !alarm;
    sub_progress_ = sub_progress_ && !progress;
  }
  /// The upload in progress (program.begin … commit), or nullptr.
  [[nodiscard]] Upload* upload() { return upload_ ? &*upload_ : nullptr; }
  /// Starts an upload, replacing any in progress.
  Upload& begin_upload(Upload u) { return upload_.emplace(std::move(u)); }
  void end_upload() { upload_.reset(); }
  /// The variables this session traces from now on (the server's taps follow).
  void set_trace_vars(std::vector<std::string> names) {
    trace_vars_ = std::move(names);
    server_.retrace();
  }
};

/// Runs one request for a session (ops.cpp).
OpResult run_op(Session& s, const ParsedRequest& req);

}  // namespace edm::bridge
