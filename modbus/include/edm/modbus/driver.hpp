#pragma once
// The `modbus` I/O driver (docs/modbus.md): edmplc as a Modbus TCP client of remote I/O.
//
//   exchange thread (non-RT, start()..stop())        I/O task (RT)
//   connect, backoff on failure  ──────────────┐     read_inputs():  take the newest input
//   every poll_interval: write outputs (FC15/16),    image (wait-free), copy it to the pins;
//   read inputs (FC1/2/3/4), decode + scale  ──┼──▶  age it; too old → alarm 121 io_stale
//   into the input image, publish            ◀─┼───  write_outputs(): pins (or the safe values
//   take the newest output image, encode      │      in FAULT/ESTOP) into the output image
//
// Both images are TripleBuffers: the RT side never waits, locks, allocates or logs; a slow or
// absent remote only makes the input image older. An image older than `stale_cycles` cycles of
// the I/O task raises alarm 121 (fault: the safe state) every cycle while it lasts, cleared when
// fresh images come again (the operator resets). Inputs with `safety: estop` read false →
// E-stop (alarm 130); `safety: interlock` false → alarm 131 interlock_open (fault); both only
// judged on a fresh image.
//
// Thread-safety: the RT methods from the I/O task's thread; start()/stop() from the controlling
// thread; the counters from any thread.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "edm/modbus/pin_map.hpp"
#include "edm/modbus/triple_buffer.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/type_registry.hpp"

namespace edm::modbus {

struct ModbusDriverParams {
  std::string host{"127.0.0.1"};
  std::int64_t port{502};
  std::int64_t unit_id{1};
  rt::Duration poll_interval{std::chrono::milliseconds(10)};
  rt::Duration response_timeout{std::chrono::milliseconds(100)};
  std::int64_t stale_cycles{100};
  rt::Duration reconnect_min{std::chrono::milliseconds(100)};
  rt::Duration reconnect_max{std::chrono::seconds(5)};
  std::string online_pin;  // a BOOL output pin, true while the image is fresh; "" = none

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class ModbusDriver final : public rt::BlockWithParams<ModbusDriverParams, rt::IoDriver> {
 public:
  ModbusDriver();
  ~ModbusDriver() override;

  [[nodiscard]] bool has_pin_map() const noexcept override { return true; }
  std::vector<rt::PinMapError> set_pin_map(const std::vector<rt::PinMapEntry>& entries) override;
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  void visit_pins(rt::PinVisitor& v) override;
  void activate() noexcept override;

  void read_inputs(const rt::CycleContext& ctx) noexcept override;
  void write_outputs(const rt::CycleContext& ctx) noexcept override;
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;
  void start() override;
  /// A field bus: its image ages in wall time.
  [[nodiscard]] bool wall_time_io() const noexcept override { return true; }
  void stop() noexcept override;

  /// Counters of the exchange thread. Any thread.
  struct Counters {
    std::uint64_t exchanges{0};  // complete read+write rounds
    std::uint64_t errors{0};     // failed requests (the connection is then closed)
    std::uint64_t connects{0};   // successful connections
    std::uint64_t clamped{0};    // output values clamped to their type's range
  };
  [[nodiscard]] Counters counters() const noexcept;
  [[nodiscard]] const std::vector<PinMapping>& pin_map() const noexcept { return map_; }

 private:
  struct Image {
    std::vector<double> values;  // one per mapping, in map_ order (bits 0/1)
    std::uint64_t seq{0};
  };
  struct Span;  // a run of adjacent addresses in one table, one request (driver.cpp)
  struct Link;  // the libmodbus context (driver.cpp)

  void run_exchange() noexcept;
  bool exchange_once(Link& link) noexcept;
  void sleep_for(rt::Duration d);
  void publish_safe_outputs() noexcept;

  std::vector<PinMapping> map_;
  std::vector<std::unique_ptr<rt::Output<bool>>> bit_in_;
  std::vector<std::unique_ptr<rt::Input<bool>>> bit_out_;
  std::vector<std::unique_ptr<rt::Output<double>>> reg_in_;
  std::vector<std::unique_ptr<rt::Input<double>>> reg_out_;
  std::vector<std::size_t> pin_slot_;  // map_ index → index into the vector of its kind
  rt::Output<bool> online_;
  std::vector<Span> reads_;
  std::vector<Span> writes_;

  TripleBuffer<Image> in_;   // exchange thread → RT
  TripleBuffer<Image> out_;  // RT → exchange thread

  // RT side
  rt::Machine* machine_{nullptr};
  std::uint64_t seen_seq_{0};
  std::uint64_t age_{0};  // I/O-task cycles since the last new input image
  bool stale_{false};
  std::vector<bool> interlock_open_;  // per mapping
  std::string stale_source_;          // "io.<first pin>": alarm sources live as long as this
  std::vector<std::string> pin_sources_;

  // exchange thread
  std::unique_ptr<Link> link_;  // made by start(); the thread's afterwards
  std::thread thread_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  bool stopping_{false};  // guarded by wake_mutex_
  std::atomic<std::uint64_t> exchanges_{0};
  std::atomic<std::uint64_t> errors_{0};
  std::atomic<std::uint64_t> connects_{0};
  std::atomic<std::uint64_t> clamped_{0};
  std::uint64_t seq_{0};
};

/// Registers "modbus".
void register_modbus_driver(rt::DriverRegistry& r);

}  // namespace edm::modbus
