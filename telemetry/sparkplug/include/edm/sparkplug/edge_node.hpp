#pragma once
// A Sparkplug B edge node with one device over MQTT (libmosquitto): births, deaths (NDEATH is the
// MQTT Last Will, carrying bdSeq), seq 0..255, report by exception with per-metric deadbands,
// bounded store and forward while the broker is away, TLS and username/password. NCMD/DCMD go to
// the owner's command sink as they arrive; the owner screens and decodes them on its own thread
// (edmplc: telemetry's CommandIntake) and answers a rebirth with request_rebirth().
// docs/mqtt.md describes the topics and the behaviour.
//
// Threads: libmosquitto's network thread (mosquitto_loop_start) connects, reconnects and
// receives; it only records what happened (connected, why a connect failed) under a mutex and
// hands commands to the sink (which must be quick and bounded: a size check and a copy). That
// thread ends for good after a TLS error (libmosquitto's loop treats it as fatal): tick() starts it
// again, 1 s doubling to reconnect_max_s, like libmosquitto's own reconnects. Everything that
// publishes runs on the owner's thread in tick(): births after a (re)connect or a rebirth request,
// replays and data, so seq numbers are assigned in one place. start(), tick() and stop() from one
// owner thread; stats() from any thread. Never on an RT thread (allocates, locks, syscalls).

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "edm/sparkplug/sparkplug.hpp"

struct mosquitto;
struct mosquitto_message;

namespace edm::sparkplug {

class EdgeNodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MetricDef {
  std::string name;
  DataType type{DataType::kDouble};
  double deadband{0.0};  // numeric metrics: report when |new - last reported| > deadband
};

struct TlsOptions {
  std::string ca_file;    // PEM CA certificate(s) the broker's certificate must chain to
  std::string cert_file;  // client certificate (optional, with key_file)
  std::string key_file;
  bool verify_hostname{true};
};

struct EdgeNodeOptions {
  std::string host{"127.0.0.1"};
  int port{1883};
  std::string group;
  std::string node;
  std::string device;     // the one device (DBIRTH/DDATA/DDEATH/DCMD)
  std::string client_id;  // empty: "<group>:<node>"
  int keepalive_s{10};
  std::string username;  // empty: none
  std::string password;
  std::optional<TlsOptions> tls;
  std::vector<MetricDef> device_metrics;
  /// DDATA payloads kept while the broker is away, replayed (is_historical) after the births;
  /// beyond it the oldest is dropped and counted. 0: nothing is kept.
  std::size_t store_capacity{1024};
  /// An NDATA with the node's counters at least this often while connected (0: only when they
  /// change), so a fleet view that just joined hears of an idle node and can ask for a rebirth.
  std::chrono::milliseconds heartbeat{std::chrono::seconds(2)};
  int reconnect_min_s{1};
  int reconnect_max_s{8};
  /// Informational lines (connected, connection lost); may be empty.
  std::function<void(const std::string&)> log;
  /// Why a connect failed (refused by the broker: credentials; TLS: certificate), once per
  /// distinct reason until a connect succeeds; empty: `log`.
  std::function<void(const std::string&)> warn;
};

/// An NCMD/DCMD as it arrives (topic, payload, the MQTT retain flag), on libmosquitto's network
/// thread: the sink must not block, decode or keep more than it bounds.
using CommandSink =
    std::function<void(std::string_view topic, std::string_view payload, bool retained)>;

/// The owner's command counters, published in NBIRTH/NDATA (Commands/…).
struct CommandCounters {
  std::uint64_t accepted{0};
  std::uint64_t refused{0};
  std::uint64_t dropped{0};       // dropped unread (limits, framing, topic, retained)
  std::uint64_t out_of_range{0};  // refused for their value's type or range
};

struct EdgeNodeStats {
  bool connected{false};
  std::uint64_t connects{0};
  std::uint64_t bdseq{0};
  std::uint64_t births{0};     // NBIRTH+DBIRTH pairs published
  std::uint64_t published{0};  // messages handed to the broker connection
  std::uint64_t stored{0};     // DDATA payloads stored while away (total)
  std::uint64_t queued{0};     // DDATA payloads in the store now
  std::uint64_t dropped{0};    // oldest stored payloads dropped at capacity
  std::uint64_t replayed{0};   // stored payloads published after a reconnect
  std::uint64_t commands_accepted{0};
  std::uint64_t commands_refused{0};
  std::uint64_t commands_dropped{0};
  std::uint64_t commands_out_of_range{0};
};

class EdgeNode {
 public:
  /// Throws EdgeNodeError on bad options (ids, TLS files, capacity). Without a sink, commands
  /// (Rebirth too) are ignored.
  EdgeNode(EdgeNodeOptions options, CommandSink on_command);
  ~EdgeNode();
  EdgeNode(const EdgeNode&) = delete;
  EdgeNode& operator=(const EdgeNode&) = delete;

  /// Registers the will (NDEATH, bdSeq) and starts connecting in the background (a broker that
  /// is not there yet is retried). Throws EdgeNodeError when libmosquitto refuses the setup.
  void start();
  /// One step: births after a (re)connect or a rebirth request, then stored data, then the device
  /// values that changed beyond their deadband (one DDATA), then the node's NDATA when due.
  /// `values` in the order of options.device_metrics; `t_ms` their capture time.
  void tick(std::span<const Value> values, std::uint64_t t_ms);
  /// Publishes DDEATH and NDEATH (a clean stop: the broker then drops the will), disconnects and
  /// joins the network thread. Idempotent.
  void stop();

  /// Births again at the next tick (Node Control/Rebirth). Thread-safe.
  void request_rebirth();
  /// The counters the next NBIRTH/NDATA carry. Thread-safe.
  void set_command_counters(const CommandCounters& c) noexcept;

  [[nodiscard]] EdgeNodeStats stats() const;
  [[nodiscard]] const EdgeNodeOptions& options() const noexcept { return opt_; }

 private:
  static void on_connect_cb(mosquitto*, void* self, int rc);
  static void on_disconnect_cb(mosquitto*, void* self, int rc);
  static void on_message_cb(mosquitto*, void* self, const mosquitto_message* msg);
  static void on_log_cb(mosquitto*, void* self, int level, const char* line);

  void set_will_locked();
  bool publish(const Topic& topic, Payload& p);  // assigns seq unless NDEATH
  void publish_births(std::span<const Value> values, std::uint64_t t_ms);
  void replay_store();
  void publish_node_data(std::uint64_t t_ms, bool force);
  void store(Payload p);
  void log(const std::string& line) const;
  void warn(const std::string& line) const;
  /// A connect failed: warns once per distinct reason until a connect succeeds.
  void connect_failed(const std::string& why);
  void restart_network_thread();
  [[nodiscard]] std::string broker() const;
  [[nodiscard]] std::vector<Metric> node_counters(std::uint64_t t_ms) const;

  EdgeNodeOptions opt_;
  CommandSink on_command_;
  mosquitto* mosq_{nullptr};
  bool started_{false};
  Topic ncmd_;
  Topic dcmd_;

  // Shared with the network thread.
  mutable std::mutex mu_;
  bool connected_{false};
  bool need_birth_{false};
  bool will_used_{false};  // the current will went out in a CONNECT: the next one needs a new bdSeq
  std::uint64_t bdseq_{0};
  std::uint64_t connects_{0};
  std::vector<std::string> failures_;  // connect failures warned about since the last connect
  bool conn_refused_{false};           // the broker refused the CONNECT being closed now
  bool tls_failed_{false};             // a TLS error ended libmosquitto's network thread

  // Owner thread only.
  std::uint64_t seq_{0};
  bool birthed_{false};          // births published on the current connection
  std::vector<Value> reported_;  // last value reported (published or stored) per device metric
  bool have_reported_{false};
  std::deque<Payload> store_;
  std::vector<Value> last_counters_;
  std::chrono::steady_clock::time_point last_ndata_{};
  std::chrono::steady_clock::time_point started_at_{};
  std::chrono::steady_clock::time_point restart_at_{};  // after a TLS error; epoch: not pending
  int restart_delay_s_{0};

  std::atomic<std::uint64_t> births_{0}, published_{0}, stored_{0}, dropped_{0}, replayed_{0},
      queued_{0};
  std::atomic<std::uint64_t> cmd_accepted_{0}, cmd_refused_{0}, cmd_dropped_{0},
      cmd_out_of_range_{0};
};

}  // namespace edm::sparkplug
