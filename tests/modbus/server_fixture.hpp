#pragma once
// edmplc's Modbus TCP server in the test's process, over a runtime built from a small config
// (loopback I/O, a Gain, a LowPass and a DischargeStateCounter for a BOOL parameter), on a free
// loopback port: real sockets, the server's own counters for synchronisation. The tasks do not
// run: pins keep their first values, parameter writes wait in the task's queue.

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "edm/blocks/register.hpp"
#include "edm/modbus/server.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::test {

inline constexpr const char* kServerRuntime = R"(version: 1
machine: {name: mbs, io: {driver: loopback, params: {channels: 1}}}
tasks: [{name: t, interval: 1ms, priority: 0, programs: [p]}]
programs:
  - name: p
    blocks:
      - {name: g, type: Gain, params: {k: 2, offset: 0.5}}
      - {name: lp, type: LowPass, params: {tau: 5ms}}
      - {name: dsc, type: DischargeStateCounter}
    wires: {g.in: 1.5, io.ao0: g.out, lp.in: g.out}
)";

/// The register map of the tests: holding 0-1 p.g.k (float32, rw), 2 p.g.out (int16, r),
/// 3 p.lp.tau (ms, rw), 4-5 p.g.k again (rw), 100-224 p.g.out (r: 125 registers for the longest
/// reply), 65534-65535 p.g.k (float32, rw); input 0-1 io.ai0 (int32); coil 0 io.do0 (r), 1
/// p.dsc.arcs_as_short (rw); discrete input 0 io.di0.
inline std::string server_map() {
  std::string m = R"(  map:
    - {table: holding_register, address: 0, var: p.g.k, type: float32, writable: true}
    - {table: holding_register, address: 2, var: p.g.out, type: int16, scale: 0.01}
    - {table: holding_register, address: 3, var: p.lp.tau, type: uint16, scale: 0.001,
       writable: true}
    - {table: holding_register, address: 4, var: p.g.k, type: float32, writable: true}
    - {table: holding_register, address: 65534, var: p.g.k, type: float32, writable: true}
    - {table: input_register, address: 0, var: io.ai0, type: int32, scale: 0.001}
    - {table: coil, address: 0, var: io.do0}
    - {table: coil, address: 1, var: p.dsc.arcs_as_short, writable: true}
    - {table: discrete_input, address: 0, var: io.di0}
)";
  for (int a = 100; a < 225; ++a) {
    m += "    - {table: holding_register, address: " + std::to_string(a) + ", var: p.g.out}\n";
  }
  return m;
}

class ServerFixture {
 public:
  /// `limits`: lines of the modbus_server section before `map:` ("  max_clients: 4\n").
  explicit ServerFixture(const std::string& limits = "") {
    rt::BlockRegistry blocks;
    blocks::register_builtin_blocks(blocks);
    rt::DriverRegistry drivers;
    rt::register_runtime_drivers(drivers);
    rt_ = rt::Runtime::build(rt::parse_config_text(kServerRuntime, "mbs.yaml"), blocks, drivers);
    text_ = std::string("modbus_server:\n  port: 0\n") + limits + server_map();
    auto cfg = modbus::parse_server_text(text_, "mbs.yaml", rt_->variables());
    config_ = *cfg;
    server_ = std::make_unique<modbus::Server>(rt_->variables(), config_);
    server_->start();
  }

  [[nodiscard]] int port() const { return server_->port(); }
  [[nodiscard]] modbus::Server::Counters counters() const { return server_->counters(); }
  [[nodiscard]] const modbus::ServerConfig& config() const { return config_; }
  rt::VariableRegistry& vars() { return rt_->variables(); }
  void stop() { server_->stop(); }

  /// Polls `ok` (the server's counters, a client's state) until true or `within` passed.
  static bool eventually(const std::function<bool()>& ok,
                         std::chrono::milliseconds within = std::chrono::seconds(5)) {
    const auto end = std::chrono::steady_clock::now() + within;
    while (std::chrono::steady_clock::now() < end) {
      if (ok()) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return ok();
  }

 private:
  std::unique_ptr<rt::Runtime> rt_;
  std::string text_;
  modbus::ServerConfig config_;
  std::unique_ptr<modbus::Server> server_;
};

}  // namespace edm::test
