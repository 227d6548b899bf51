#pragma once
// The Modbus TCP server of edmplc (`modbus_server:`, docs/modbus.md): configured variables as
// coils, discrete inputs, input registers and holding registers, for an HMI panel or a SCADA
// system. It runs on a thread of its own, never an RT one: a read takes the variable registry's
// values (lock-free pin loads; parameters from their shadow copies), the same path as the
// bridge's var.read; a write goes through VariableRegistry::write (validated, queued to the
// owning task, applied at the start of its next cycle), and only to parameters the config marks
// `writable: true`.
//
// Exceptions: 01 illegal function (any function but 1, 2, 3, 4, 5, 6, 15, 16); 02 illegal data
// address (an address not mapped in that table, part of a 32-bit value written alone, or a
// write to a value that is not writable); 03 illegal data value (a quantity outside the
// protocol's limits, or a value the parameter's range refuses); 04 server device failure (the
// variable could not be read); 06 server device busy (the task's write queue is full).
// Frames are read by this server (MBAP checked: protocol 0, length 2..254, at most 260 bytes);
// a malformed frame closes its connection. At most `max_clients` connections; more are closed
// at once; a connection idle for `idle_timeout` is closed.
//
// Thread-safety: start()/stop() from one controlling thread; the server reads the registry from
// its own thread (the registry is thread-safe for non-RT callers).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>
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
  int max_clients{4};
  std::chrono::milliseconds idle_timeout{60000};
  std::vector<ServerEntry> map;
  rt::SourceLoc loc;
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

class Server {
 public:
  Server(rt::VariableRegistry& vars, ServerConfig config);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds and starts the thread. Throws std::runtime_error when it cannot bind.
  void start();
  void stop() noexcept;
  /// The bound port (after start(); useful with port 0).
  [[nodiscard]] int port() const noexcept { return bound_port_; }

  struct Counters {
    std::uint64_t requests{0};
    std::uint64_t exceptions{0};
    std::uint64_t writes{0};
    std::uint64_t refused_clients{0};
    std::uint64_t bad_frames{0};
  };
  [[nodiscard]] Counters counters() const noexcept;

 private:
  struct Client;
  void run() noexcept;
  // Handles one complete frame; false: close the connection.
  bool handle(Client& c, const std::uint8_t* frame, std::size_t n) noexcept;
  int read_values(Table t, std::uint16_t addr, std::uint16_t nb, std::vector<std::uint16_t>& out);
  int write_values(Table t, std::uint16_t addr, std::uint16_t nb, const std::uint16_t* words);
  // The entries covering [addr, addr+nb) of table t, or an exception code.
  const ServerEntry* entry_at(Table t, std::uint32_t addr) const noexcept;

  rt::VariableRegistry& vars_;
  ServerConfig config_;
  std::vector<std::vector<int>> index_;  // per table: address → entry index (-1 = unmapped)
  int listen_fd_{-1};
  int bound_port_{0};
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<std::uint64_t> exceptions_{0};
  std::atomic<std::uint64_t> writes_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> bad_frames_{0};
};

}  // namespace edm::modbus
