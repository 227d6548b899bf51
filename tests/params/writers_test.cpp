// Issue 31 item 13 through the real writers: the bridge's var.write (a JSON integer 2^63 - 1 for
// gap.kg, the issue's value) and the Modbus server (a float32 holding register: exception 03
// ILLEGAL DATA VALUE). Both are refused as out of range by the runtime's write entry point and the
// value stays; a value inside the range is taken. (MQTT commands call the same entry point:
// telemetry/publisher/src/publisher.cpp, on_command.)

#include <gtest/gtest.h>
#include <modbus.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

#include "edm/bridge/client.hpp"
#include "edm/bridge/server.hpp"
#include "edm/modbus/server.hpp"
#include "params/params_rig.hpp"
#include "support/runtime_thread.hpp"
#include "support/test_machine.hpp"

namespace edm::test {
namespace {

const std::string kGapMachine =
    test_machine("gap-only", "{driver: loopback, task: t, params: {channels: 1}}") + R"(tasks:
  - {name: t, interval: 1ms, priority: 0, programs: [cnc]}
programs:
  - name: cnc
    blocks:
      - {name: gap, type: GapControllerP}
)";

constexpr const char* kKg = "cnc.gap.kg";

// The float32 in two holding registers, high word first (the server's default word order).
void put_float(float f, std::uint16_t* words) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  words[0] = static_cast<std::uint16_t>(bits >> 16);
  words[1] = static_cast<std::uint16_t>(bits & 0xffffu);
}

// The machine running on the real clock (accepted writes are applied by its task), with the
// bridge and the Modbus server (holding registers 0-1: kg as a writable float32). The servers
// are made before the tasks run and stopped after them (the bridge observes the cycles).
class RunningMachine : public ::testing::Test {
 protected:
  void SetUp() override {
    rt_ = build_with_every_registry(kGapMachine, "gap-only.yaml");
    bridge::ServerOptions opt;
    opt.port = 0;
    bridge_ = std::make_unique<bridge::Server>(*rt_, opt);
    bridge_->start();
    modbus::ServerConfig cfg;
    cfg.port = 0;
    modbus::ServerEntry e;
    e.table = modbus::Table::kHoldingRegister;
    e.address = 0;
    e.var = kKg;
    e.enc.type = modbus::ValueType::kFloat32;
    e.writable = true;
    cfg.map.push_back(e);
    modbus_ = std::make_unique<modbus::Server>(rt_->variables(), cfg);
    modbus_->start();
    runner_.start(*rt_);  // the real clock
    ASSERT_TRUE(runner_.wait_until_powered_on()) << "the runtime did not start";
  }
  void TearDown() override {
    runner_.stop();
    if (modbus_) {
      modbus_->stop();
    }
    if (bridge_) {
      bridge_->stop();
    }
  }
  double kg() { return *rt_->variables().read(kKg); }

  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<bridge::Server> bridge_;
  std::unique_ptr<modbus::Server> modbus_;
  RuntimeThread runner_;
};

TEST_F(RunningMachine, TheBridgeRefusesGapKgAt2To63AsOutOfRangeAndKeepsTheValue) {
  bridge::Client client;
  bridge::ClientOptions co;
  co.port = bridge_->port();
  co.timeout = std::chrono::seconds(10);
  ASSERT_EQ(client.connect(co), bridge::Role::kOperator);
  const double before = kg();

  bridge::Json big = bridge::Json::object();
  big["name"] = kKg;
  big["value"] = std::int64_t{9223372036854775807};  // a JSON integer, as a client sends it
  const bridge::Reply r = client.request("var.write", big);
  EXPECT_FALSE(r);
  ASSERT_TRUE(r.code.has_value()) << r.message;
  EXPECT_EQ(*r.code, bridge::ErrorCode::kBadRequest);
  EXPECT_NE(r.message.find("out of range: must be in (0, 10] mm/s/us (got 9.22337e18)"),
            std::string::npos)
      << r.message;
  for (const double x : {0.0, -1.0, 10.000001}) {
    const bridge::Reply o = client.request("var.write", {{"name", kKg}, {"value", x}});
    EXPECT_FALSE(o) << x;
    EXPECT_NE(o.message.find("out of range"), std::string::npos) << o.message;
  }
  const bridge::Reply read = client.request("var.read", {{"names", {kKg}}});
  ASSERT_TRUE(read) << read.message;
  EXPECT_EQ(read.body["values"][kKg].get<double>(), before);
  EXPECT_EQ(kg(), before);

  EXPECT_TRUE(client.request("var.write", {{"name", kKg}, {"value", 10.0}}));
  EXPECT_EQ(kg(), 10.0);
  client.close();
}

TEST_F(RunningMachine, TheModbusServerAnswersAnOutOfRangeWriteWithException03) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", modbus_->port());
  ASSERT_NE(ctx, nullptr);
  ASSERT_EQ(modbus_connect(ctx), 0) << modbus_strerror(errno);
  const double before = kg();

  std::uint16_t w[2];
  for (const float x : {9.2e18f, -1.0f, 0.0f, 11.0f}) {
    put_float(x, w);
    errno = 0;
    EXPECT_EQ(modbus_write_registers(ctx, 0, 2, w), -1) << x;
    EXPECT_EQ(errno, EMBXILVAL) << x << ": " << modbus_strerror(errno);
  }
  EXPECT_EQ(kg(), before);
  put_float(0.25f, w);
  EXPECT_EQ(modbus_write_registers(ctx, 0, 2, w), 2) << modbus_strerror(errno);
  EXPECT_EQ(kg(), 0.25);
  modbus_close(ctx);
  modbus_free(ctx);
}

}  // namespace
}  // namespace edm::test
