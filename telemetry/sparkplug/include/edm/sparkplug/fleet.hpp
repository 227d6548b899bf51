#pragma once
// The fleet as a Sparkplug host application sees it (`edmhmi fleet`, docs/mqtt.md): every node and
// device heard on `spBv1.0/#`, rebuilt from births, data and deaths. A node heard from without its
// birth (the view joined late) is asked for one with NCMD "Node Control/Rebirth".
// Anyone who may publish on the broker can feed the view: payloads are screened before they are
// decoded (inbound.hpp, FleetLimits), and the table is bounded in nodes, devices and metrics
// (what does not fit is ignored and counted); the terminal table shows no control characters.
// FleetTable: thread-compatible, no I/O. FleetWatcher: its own libmosquitto network thread;
// machines() from any thread.

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "edm/sparkplug/edge_node.hpp"
#include "edm/sparkplug/inbound.hpp"
#include "edm/sparkplug/sparkplug.hpp"

struct mosquitto;
struct mosquitto_message;

namespace edm::sparkplug {

struct FleetMachine {
  std::string group;
  std::string node;
  std::string device;  // empty: a node without devices
  bool online{false};  // births seen, no death since
  bool born{false};    // a birth has been seen (the metrics below are complete)
  std::uint64_t bdseq{0};
  std::uint64_t seq_gaps{0};  // messages whose seq was not the previous + 1 (mod 256)
  std::uint64_t last_seen_ms{0};
  std::map<std::string, Value> metrics;       // the device's (or the node's, without device)
  std::map<std::string, Value> node_metrics;  // the node's

  /// A metric as text, "-" when absent.
  [[nodiscard]] std::string text(std::string_view name) const;
  /// "running 5/15 (33 %) line 40", "finished 15/15", "-"
  [[nodiscard]] std::string job() const;
};

/// What the view keeps of what it hears.
struct FleetLimits {
  InboundLimits payload{1 << 20, 4096};  // a birth of a large node still fits
  std::size_t max_nodes{4096};
  std::size_t max_id_bytes{128};  // group, node and device ids (a topic may be 64 KiB)
  std::size_t max_devices_per_node{256};
  std::size_t max_metrics{100000};     // metric values kept, all machines together
  std::size_t max_name_bytes{256};     // a longer metric name is not kept
  std::size_t max_string_bytes{1024};  // a longer string value is cut
};

class FleetTable {
 public:
  explicit FleetTable(FleetLimits limits = {}) : limits_(limits) {}
  /// Applies one message (anything that is not Sparkplug B is ignored).
  void on_message(std::string_view topic, std::string_view payload, std::uint64_t now_ms);
  /// Every machine, sorted by group, node, device.
  [[nodiscard]] std::vector<FleetMachine> machines() const;
  /// Nodes (group, node) heard from without a birth since the last call.
  std::vector<std::pair<std::string, std::string>> take_rebirth_requests();
  /// Messages ignored whole (screened out, undecodable, no room for their node or device) and
  /// metric values not kept (no room, name too long).
  [[nodiscard]] std::uint64_t ignored_messages() const noexcept { return ignored_messages_; }
  [[nodiscard]] std::uint64_t ignored_metrics() const noexcept { return ignored_metrics_; }
  [[nodiscard]] std::size_t metrics_kept() const noexcept { return kept_; }

 private:
  struct Node {
    bool online{false};
    bool born{false};
    std::uint64_t bdseq{0};
    std::optional<std::uint64_t> last_seq;
    std::uint64_t seq_gaps{0};
    std::uint64_t last_seen_ms{0};
    std::map<std::string, Value> metrics;
    std::map<std::string, FleetMachine> devices;  // by device id
  };
  void apply(std::map<std::string, Value>& into, const Payload& from, bool clear);

  FleetLimits limits_;
  std::size_t kept_{0};  // metric values in all the maps
  std::uint64_t ignored_messages_{0};
  std::uint64_t ignored_metrics_{0};
  std::map<std::pair<std::string, std::string>, Node> nodes_;
  std::set<std::pair<std::string, std::string>> rebirth_;
  std::set<std::pair<std::string, std::string>> asked_;
};

/// The table as text columns (one machine a line) or as JSON (one array).
std::string render_text(const std::vector<FleetMachine>& machines, std::uint64_t now_ms);
std::string render_json(const std::vector<FleetMachine>& machines, std::uint64_t now_ms);

struct FleetOptions {
  std::string host{"127.0.0.1"};
  int port{1883};
  std::string group;  // empty: every group
  std::string client_id;
  std::string username;
  std::string password;
  std::optional<TlsOptions> tls;
  bool ask_rebirth{true};  // NCMD Rebirth to nodes heard without a birth
};

class FleetWatcher {
 public:
  explicit FleetWatcher(FleetOptions options);
  ~FleetWatcher();
  FleetWatcher(const FleetWatcher&) = delete;
  FleetWatcher& operator=(const FleetWatcher&) = delete;

  /// Connects and subscribes; throws EdgeNodeError when the broker cannot be reached.
  void start();
  /// Sends the rebirth requests that are due (call now and then from the owner's thread).
  void poll();
  [[nodiscard]] std::vector<FleetMachine> machines() const;
  [[nodiscard]] bool connected() const;

 private:
  static void on_connect_cb(mosquitto*, void* self, int rc);
  static void on_message_cb(mosquitto*, void* self, const mosquitto_message* msg);

  FleetOptions opt_;
  mosquitto* mosq_{nullptr};
  mutable std::mutex mu_;
  FleetTable table_;
  bool connected_{false};
  int connack_{-1};
};

}  // namespace edm::sparkplug
