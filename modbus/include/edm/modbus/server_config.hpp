#pragma once
// The `modbus_server:` section (docs/modbus.md): the register map of configured variables and
// the server's limits, every one with a default. Read from the config file like `mqtt:`, checked
// against the variable registry, every problem reported at its value (file:line:col).
// Non-RT (load time). Thread-safety: pure functions of their arguments.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "edm/modbus/pin_map.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/variables.hpp"

namespace edm::modbus {

/// One value of the register map.
struct ServerEntry {
  Table table{Table::kHoldingRegister};
  std::uint16_t address{0};
  std::string var;
  Encoding enc;  // bits: kBool
  bool writable{false};
  std::string unit;  // the variable's, for the printed map
  rt::SourceLoc loc;
};

struct ServerConfig {
  std::string bind{"127.0.0.1"};
  int port{1502};
  /// Connections at once (1-64).
  int max_clients{16};
  /// Connections at once from one peer address (1..max_clients); 0: a quarter of max_clients,
  /// at least 1 (resolved by effective_per_address()).
  int max_clients_per_address{0};
  /// A frame begun must be complete this long after its first byte, and a reply must be taken
  /// by the client within it; else the connection is closed.
  std::chrono::milliseconds frame_timeout{1000};
  /// A connection without a complete request this long is closed.
  std::chrono::milliseconds idle_timeout{60000};
  /// Log lines about one peer address: this many at once, then log_per_s a second.
  int log_burst{10};
  double log_per_s{1.0};
  std::vector<ServerEntry> map;
  rt::SourceLoc loc;

  [[nodiscard]] int effective_per_address() const noexcept {
    if (max_clients_per_address > 0) {
      return max_clients_per_address;
    }
    return max_clients >= 4 ? max_clients / 4 : 1;
  }
};

/// The `modbus_server:` section of cfg.path checked against `vars`; nullopt when absent. Throws
/// rt::ConfigError listing every problem (file:line:col).
std::optional<ServerConfig> load_server_config(const rt::Config& cfg,
                                               const rt::VariableRegistry& vars);
/// The same from text (tests).
std::optional<ServerConfig> parse_server_text(const std::string& text, const std::string& path,
                                              const rt::VariableRegistry& vars);

/// The register map as a table (edmplc --modbus-map, docs/modbus.md).
std::string format_register_map(const ServerConfig& c);

}  // namespace edm::modbus
