#pragma once
// The `mqtt:` section of a machine config (docs/mqtt.md): broker, Sparkplug ids, the metrics and
// their deadbands, store and forward, credentials, TLS and commands. The runtime's parser only
// notes where the section is (rt::Config::mqtt_loc); this reads it from the same file and checks
// it against the built runtime's variables, every problem as file:line:col (rt::ConfigError).
// Non-RT; thread-compatible.

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "edm/runtime/config.hpp"
#include "edm/runtime/variables.hpp"
#include "edm/sparkplug/edge_node.hpp"
#include "edm/sparkplug/inbound.hpp"

namespace edm::telemetry {

/// A variable published as a device metric.
struct MetricSpec {
  std::string var;   // the runtime variable (pin or parameter)
  std::string name;  // the Sparkplug metric name (default: var)
  double deadband{0.0};
  rt::SourceLoc loc;
};

struct MqttConfig {
  std::string host;
  int port{1883};
  std::string group;
  std::string node;
  std::string device;     // default: machine.name (when it is a valid id), else "machine"
  std::string client_id;  // default: "<group>:<node>"
  std::chrono::milliseconds interval{100};    // how often values are compared (report by exception)
  std::chrono::milliseconds heartbeat{2000};  // node NDATA at least this often (0: off)
  std::chrono::seconds keepalive{10};
  double deadband{0.0};  // default for metrics without their own
  std::vector<MetricSpec> metrics;
  std::size_t store_forward{1000};  // DDATA payloads kept while the broker is away
  std::string username;
  std::string password;  // read from password_file
  std::optional<sparkplug::TlsOptions> tls;
  sparkplug::InboundLimits limits;  // what one NCMD/DCMD may be (mqtt.limits)
  bool commands_enabled{false};
  std::vector<std::string> writable;  // parameters NCMD/DCMD may write when enabled
  rt::SourceLoc loc;
};

/// The section of cfg.path, checked against `vars`; nullopt when the config has no `mqtt:`.
/// Throws rt::ConfigError listing every problem.
std::optional<MqttConfig> load_mqtt_config(const rt::Config& cfg, const rt::VariableRegistry& vars);
/// The same from text (tests); `path` names the file in messages and anchors relative paths.
std::optional<MqttConfig> parse_mqtt_text(const std::string& text, const std::string& path,
                                          const std::string& machine_name,
                                          const rt::VariableRegistry& vars);

}  // namespace edm::telemetry
