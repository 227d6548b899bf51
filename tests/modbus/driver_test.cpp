// The modbus I/O driver against Debian's pymodbus as the remote I/O (docs/modbus.md): values
// both ways with scaling, the stale image → alarm 121 → the safe state, reconnection, the
// safety contacts, and pin-map errors at file:line:col. An edmplc runtime in this process, on
// the real clock.

#include "edm/modbus/driver.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <thread>

#include "edm/blocks/register.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "modbus/remote_io.hpp"
#include "support/runtime_thread.hpp"

namespace edm::modbus {
namespace {

using namespace std::chrono_literals;

std::string config_text(int port, const std::string& extra_pins = "",
                        const std::string& extra_wires = "") {
  return R"(version: 1
machine:
  name: mbtest
  io:
    driver: modbus
    params: {host: 127.0.0.1, port: )" +
         std::to_string(port) + R"(, poll_interval: 5ms, response_timeout: 50ms,
             stale_cycles: 200, reconnect_min: 20ms, reconnect_max: 200ms, online_pin: online}
    pins:
      - {name: door_closed, table: discrete_input, address: 0}
      - {name: pressure_bar, table: input_register, address: 0, type: int16, scale: 0.01}
      - {name: count, table: input_register, address: 10, type: int32}
      - {name: flow, table: input_register, address: 20, type: float32, word_order: little}
      - {name: pump, table: coil, address: 0}
      - {name: valve, table: coil, address: 1, safe: true}
      - {name: speed_rpm, table: holding_register, address: 0, type: uint16, scale: 0.1,
         offset: 5}
      - {name: setpoint, table: holding_register, address: 10, type: float32}
)" + extra_pins +
         R"(
tasks:
  - {name: io, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks: []
    wires:
      io.pump: true
      io.valve: false
      io.speed_rpm: 25.0
      io.setpoint: -3.5
)" + extra_wires;
}

struct Running {
  std::unique_ptr<rt::Runtime> rt;
  edm::test::RuntimeThread thread;

  explicit Running(const std::string& text) {
    rt::BlockRegistry blocks;
    blocks::register_builtin_blocks(blocks);
    rt::DriverRegistry drivers;
    rt::register_runtime_drivers(drivers);
    register_modbus_driver(drivers);
    rt = rt::Runtime::build(rt::parse_config_text(text, "mbtest.yaml"), blocks, drivers);
    thread.start(*rt);
  }
  ~Running() { thread.stop(); }
  double read(const std::string& name) { return rt->variables().read(name).value_or(NAN); }
  bool has_alarm(rt::AlarmCode code) {
    std::array<rt::ActiveAlarm, 64> a{};
    const std::size_t n = rt->machine().active_alarms(a.data(), a.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (a[i].code == code) {
        return true;
      }
    }
    return false;
  }
};

bool eventually(const std::function<bool()>& ok, std::chrono::milliseconds within = 5000ms) {
  const auto end = std::chrono::steady_clock::now() + within;
  while (std::chrono::steady_clock::now() < end) {
    if (ok()) {
      return true;
    }
    std::this_thread::sleep_for(5ms);
  }
  return ok();
}

TEST(ModbusDriver, ValuesFlowBothWaysWithScaling) {
  test::RemoteIo io;
  ASSERT_TRUE(io.ready()) << io.output();
  ASSERT_TRUE(io.set("di", 0, 1));
  ASSERT_TRUE(io.set("ir", 0, 65536 - 1234));  // int16 -1234 → -12.34 bar
  ASSERT_TRUE(io.set("ir", 10, 0xFFFE));       // int32 0xFFFE0001 (high word first)
  ASSERT_TRUE(io.set("ir", 11, 0x0001));
  float f = 2.75F;  // float32, low word first
  std::uint32_t u = 0;
  std::memcpy(&u, &f, 4);
  ASSERT_TRUE(io.set("ir", 20, static_cast<int>(u & 0xFFFF)));
  ASSERT_TRUE(io.set("ir", 21, static_cast<int>(u >> 16)));

  Running r(config_text(io.port()));
  ASSERT_TRUE(eventually([&] { return r.read("io.online") == 1.0; }));
  EXPECT_EQ(r.read("io.door_closed"), 1.0);
  EXPECT_NEAR(r.read("io.pressure_bar"), -12.34, 1e-9);
  EXPECT_EQ(r.read("io.count"), static_cast<double>(static_cast<std::int32_t>(0xFFFE0001U)));
  EXPECT_EQ(r.read("io.flow"), 2.75);
  // Outputs: coil 0 on, coil 1 off; speed (25 - 5) / 0.1 = 200; setpoint -3.5 as float32 ABCD.
  ASSERT_TRUE(eventually([&] { return io.get("co", 0) == 1; }));
  EXPECT_EQ(io.get("co", 1), 0);
  EXPECT_EQ(io.get("hr", 0), 200);
  float sp = -3.5F;
  std::memcpy(&u, &sp, 4);
  EXPECT_EQ(io.get("hr", 10), static_cast<int>(u >> 16));
  EXPECT_EQ(io.get("hr", 11), static_cast<int>(u & 0xFFFF));
  // A change on the remote side reaches the pin within a few polls.
  ASSERT_TRUE(io.set("ir", 0, 500));
  EXPECT_TRUE(eventually([&] { return std::abs(r.read("io.pressure_bar") - 5.0) < 1e-9; }));
  EXPECT_EQ(r.rt->machine().state(), rt::MachineState::kReady);
}

TEST(ModbusDriver, ServerGoneIsAStaleImageAlarm121AndTheSafeStateThenReconnects) {
  test::RemoteIo io;
  ASSERT_TRUE(io.ready()) << io.output();
  Running r(config_text(io.port()));
  ASSERT_TRUE(eventually([&] { return io.get("co", 0) == 1; }));
  ASSERT_EQ(r.rt->machine().state(), rt::MachineState::kReady);

  io.kill();
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(eventually([&] { return r.rt->machine().state() == rt::MachineState::kFault; }));
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0)
          .count();
  EXPECT_TRUE(r.has_alarm(rt::AlarmCode::kIoStale));
  EXPECT_EQ(r.rt->machine().last_cause(), rt::AlarmCode::kIoStale);
  EXPECT_EQ(r.read("io.online"), 0.0);
  std::printf("stale → FAULT %lld ms after the server was killed (stale_cycles 200 at 1 ms)\n",
              static_cast<long long>(ms));
  EXPECT_LT(ms, 1000);

  // The coupler comes back on the same port: the driver reconnects with its backoff, the
  // alarm's condition clears, and in FAULT the outputs it writes are the safe values (valve's
  // safe value is true) whatever the program says.
  io.start();
  ASSERT_TRUE(io.ready()) << io.output();
  ASSERT_TRUE(eventually([&] { return r.read("io.online") == 1.0; }, 10000ms));
  auto* d = dynamic_cast<ModbusDriver*>(&r.rt->driver());
  ASSERT_NE(d, nullptr);
  EXPECT_GE(d->counters().connects, 2U);
  ASSERT_TRUE(eventually([&] { return io.get("co", 1) == 1; }));
  EXPECT_EQ(io.get("co", 0), 0);
  EXPECT_TRUE(eventually([&] { return !r.has_alarm(rt::AlarmCode::kIoStale); }));
  EXPECT_EQ(r.rt->machine().state(), rt::MachineState::kFault);  // until the operator resets
  ASSERT_EQ(r.rt->machine().command(rt::MachineCommand::kReset), rt::CommandResult::kOk);
  EXPECT_TRUE(eventually([&] { return io.get("co", 0) == 1 && io.get("co", 1) == 0; }));
  EXPECT_EQ(r.rt->machine().state(), rt::MachineState::kReady);
}

TEST(ModbusDriver, NoServerAtAllFaultsAfterStaleCycles) {
  Running r(config_text(test::free_port()));
  ASSERT_TRUE(eventually([&] { return r.rt->machine().state() == rt::MachineState::kFault; }));
  EXPECT_TRUE(r.has_alarm(rt::AlarmCode::kIoStale));
}

TEST(ModbusDriver, EstopAndInterlockContactsAreInTheSafetyChain) {
  test::RemoteIo io;
  ASSERT_TRUE(io.ready()) << io.output();
  ASSERT_TRUE(io.set("di", 1, 1));
  ASSERT_TRUE(io.set("di", 2, 1));
  Running r(config_text(io.port(),
                        "      - {name: estop_ok, table: discrete_input, address: 1, safety: "
                        "estop}\n      - {name: door, table: discrete_input, address: 2, "
                        "safety: interlock}\n"));
  ASSERT_TRUE(eventually([&] { return r.read("io.online") == 1.0; }));
  EXPECT_EQ(r.rt->machine().state(), rt::MachineState::kReady);
  // The door opens: alarm 131, FAULT; a reset while it is open faults again at once.
  ASSERT_TRUE(io.set("di", 2, 0));
  ASSERT_TRUE(eventually([&] { return r.rt->machine().state() == rt::MachineState::kFault; }));
  EXPECT_TRUE(r.has_alarm(rt::AlarmCode::kInterlockOpen));
  r.rt->machine().command(rt::MachineCommand::kReset);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(r.rt->machine().state(), rt::MachineState::kFault);
  ASSERT_TRUE(io.set("di", 2, 1));
  ASSERT_TRUE(eventually([&] { return !r.has_alarm(rt::AlarmCode::kInterlockOpen); }));
  r.rt->machine().command(rt::MachineCommand::kReset);
  EXPECT_TRUE(eventually([&] { return r.rt->machine().state() == rt::MachineState::kReady; }));
  // The E-stop chain opens: ESTOP (alarm 130).
  ASSERT_TRUE(io.set("di", 1, 0));
  ASSERT_TRUE(eventually([&] { return r.rt->machine().state() == rt::MachineState::kEstop; }));
  EXPECT_EQ(r.rt->machine().last_cause(), rt::AlarmCode::kEstop);
  EXPECT_TRUE(eventually([&] { return io.get("co", 0) == 0; }));  // the pump off
}

// The errors of a config of `machine` (its version and machine sections) with one empty task.
std::string machine_errors(const std::string& machine) {
  const std::string text = machine + R"(tasks:
  - {name: t, interval: 1ms, priority: 0, programs: [p]}
programs:
  - {name: p, blocks: []}
)";
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
  rt::register_runtime_drivers(drivers);
  register_modbus_driver(drivers);
  try {
    rt::Runtime::build(rt::parse_config_text(text, "bad.yaml"), blocks, drivers);
  } catch (const rt::ConfigError& e) {
    std::string all;
    for (const rt::Diagnostic& d : e.diagnostics()) {
      all += d.loc.file + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) +
             ": " + d.message + "\n";
    }
    return all;
  }
  return "";
}

TEST(ModbusDriver, BadPinMapsAreReportedAtFileLineCol) {
  const std::string text = R"(version: 1
machine:
  name: bad
  io:
    driver: modbus
    params: {port: 1502}
    pins:
      - {name: a, table: coils, address: 0}
      - {name: b, table: discrete_input, address: 70000}
      - {name: c, table: input_register, address: 0, type: int64}
      - {name: d, table: input_register, address: 1, direction: out}
      - {name: e, table: coil, address: 3, scale: 2}
      - {name: f, table: holding_register, address: 5, type: int16, word_order: little}
      - {name: g, table: coil, address: 4, safety: estop}
      - {name: h, table: holding_register, address: 7, type: int32}
      - {name: i, table: holding_register, address: 8}
      - {table: coil, address: 9, colour: red}
)";
  const std::string e = machine_errors(text);
  EXPECT_NE(e.find("bad.yaml:8:26: I/O driver 'modbus': pins[0].table: unknown table 'coils'"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("bad.yaml:9:51: I/O driver 'modbus': pins[1].address"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.yaml:10:60: I/O driver 'modbus': pins[2].type"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[3].direction: input_register is read-only"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[4]: coil is a bit"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[5].word_order: applies to 32-bit types only"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[6].safety: only a bit input"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[8].address: holding_register 8 is already written"), std::string::npos)
      << e;
  EXPECT_NE(e.find("pins[9].colour: unknown key 'colour'"), std::string::npos) << e;
  EXPECT_NE(e.find("pins[9]: missing required key 'name'"), std::string::npos) << e;
}

TEST(ModbusDriver, CompositeCombinesDriversAndRefusesClashes) {
  const std::string text = R"(version: 1
machine:
  name: combo
  io:
    driver: composite
    drivers:
      - {driver: loopback, params: {channels: 1}}
      - driver: modbus
        name: rio
        params: {port: 1502}
        pins:
          - {name: ai0, table: input_register, address: 0}
)";
  const std::string e = machine_errors(text);
  EXPECT_NE(e.find("pin 'io.ai0' is declared by two drivers"), std::string::npos) << e;
  std::string ok = text;
  ok.replace(ok.find("name: ai0"), 9, "name: door");
  EXPECT_EQ(machine_errors(ok), "");
}

}  // namespace
}  // namespace edm::modbus
