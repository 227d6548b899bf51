// The hal driver (docs/hal.md): its pin map's errors at file:line:col (edmplc --check on
// tests/hal/bad/), the RT side detached (counters, scaling, safe values, the heartbeat's alarm),
// and attached to a real HAL session (values through HAL's shared memory both ways; HAL not
// running, a component name in use and a refused link are errors at the config, exit 2).

#include "edm/hal/driver.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>

#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "hal/hal_session.hpp"

namespace edm::hal {
namespace {

namespace fs = std::filesystem;
using test::HalSession;

// A machine of the hal driver with one task; pins and wires as given.
std::string machine(const std::string& component, const std::string& pins,
                    const std::string& wires = "", const std::string& params = "",
                    const std::string& interval = "1ms") {
  return "version: 1\nmachine:\n  name: haltest\n  io:\n    driver: hal\n    params: {component: " +
         component + (params.empty() ? "" : ", " + params) + "}\n    pins:\n" + pins +
         "tasks:\n  - {name: t, interval: " + interval +
         ", priority: 0, programs: [p]}\nprograms:\n"
         "  - name: p\n    blocks: []\n" +
         (wires.empty() ? "" : "    wires:\n" + wires);
}

const std::string kPins =
    "      - {name: x_mm, hal: x-pos-fb, type: float, direction: in, scale: 0.001}\n"
    "      - {name: n_short, type: u32, direction: in, counter: true}\n"
    "      - {name: level, type: s32, direction: in}\n"
    "      - {name: door, type: bit, direction: in}\n"
    "      - {name: beat, type: u32, direction: in, role: heartbeat}\n"
    "      - {name: gen_on, type: bit, direction: out, safe: false}\n"
    "      - {name: vz_cmd, type: float, direction: out, safe: 0, safe_in: estop, scale: 2}\n"
    "      - {name: steps, type: s32, direction: out, scale: 0.5}\n"
    "      - {name: plc_beat, type: u32, direction: out, role: heartbeat_out}\n";
const std::string kWires = "      io.gen_on: true\n      io.vz_cmd: -3.0\n      io.steps: 20.8\n";

struct Built {
  std::unique_ptr<rt::Runtime> rt;
  HalDriver* driver{nullptr};
  rt::VirtualClock clock;
  std::int64_t k{0};

  Built(const std::string& text, bool attach) {
    rt::BlockRegistry blocks;
    rt::DriverRegistry drivers;
    register_hal_driver(drivers, attach);
    rt = rt::Runtime::build(rt::parse_config_text(text, "hal.yaml"), blocks, drivers);
    driver = dynamic_cast<HalDriver*>(&rt->driver());
    rt->machine().command(rt::MachineCommand::kPowerOn);
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i, ++k) {
      const rt::TimePoint release{std::chrono::milliseconds(k)};
      clock.advance_to(release);
      rt->tasks()[0]->run_cycle(release, clock);
    }
  }
  double read(const std::string& v) { return rt->variables().read(v).value_or(-999.0); }
  [[nodiscard]] std::size_t index(const std::string& name) const {
    const auto& m = driver->pin_map();
    for (std::size_t i = 0; i < m.size(); ++i) {
      if (m[i].name == name) return i;
    }
    return SIZE_MAX;
  }
  bool has_alarm(rt::AlarmCode code) {
    std::array<rt::ActiveAlarm, 64> a{};
    const std::size_t n = rt->machine().active_alarms(a.data(), a.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (a[i].code == code) return true;
    }
    return false;
  }
};

// Every file in tests/hal/bad/ says on line 1 `# expect: LINE:COL: text`: `edmplc --check`
// exits 2 and prints `<file>:LINE:COL: ...text...`.
TEST(HalConfig, BadConfigsAreRefusedAtFileLineColByEdmplcCheck) {
  const fs::path dir = fs::path(EDM_TEST_DATA_DIR) / "hal" / "bad";
  int cases = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".yaml") continue;
    ++cases;
    std::ifstream in(e.path());
    std::string header;
    std::getline(in, header);
    const std::string prefix = "# expect: ";
    ASSERT_EQ(header.rfind(prefix, 0), 0u) << e.path();
    const std::string expect = e.path().string() + ":" + header.substr(prefix.size());
    apps::SpawnOptions o;
    o.err = apps::Stream::kStdout;
    const apps::RunResult r = apps::run({EDM_EDMPLC_PATH, "--config", e.path().string(), "--check"},
                                        o, std::chrono::seconds(30));
    EXPECT_EQ(r.exit_code, 2) << e.path() << "\n" << r.out;
    EXPECT_NE(r.out.find(expect), std::string::npos) << "expected: " << expect << "\ngot:\n"
                                                     << r.out;
  }
  EXPECT_GE(cases, 8);
}

TEST(HalDriverDetached, InputsScaleCountAndOutputsHoldTheirSafeValues) {
  Built b(machine("edmtest", kPins, kWires), /*attach=*/false);
  ASSERT_NE(b.driver, nullptr);
  EXPECT_FALSE(b.driver->attached());
  b.driver->set_raw(b.index("x_mm"), 12345.0);  // µm on the HAL side, scale 0.001
  b.driver->set_raw(b.index("n_short"), 4294967290.0);
  b.driver->set_raw(b.index("level"), -7.0);
  b.driver->set_raw(b.index("door"), 1.0);
  b.cycles(1);
  EXPECT_DOUBLE_EQ(b.read("io.x_mm"), 12.345);
  EXPECT_EQ(b.read("io.n_short"), 0.0) << "a counter's first cycle is its base";
  EXPECT_EQ(b.read("io.level"), -7.0);
  EXPECT_EQ(b.read("io.door"), 1.0);
  b.driver->set_raw(b.index("n_short"), 3.0);  // wrapped: 4294967290 → 3 is 9 pulses
  b.cycles(1);
  EXPECT_EQ(b.read("io.n_short"), 9.0);
  b.cycles(1);
  EXPECT_EQ(b.read("io.n_short"), 0.0) << "no new pulses";
  EXPECT_EQ(b.driver->raw(b.index("gen_on")), 1.0);
  EXPECT_EQ(b.driver->raw(b.index("vz_cmd")), -1.5) << "raw = value / scale";
  EXPECT_EQ(b.driver->raw(b.index("steps")), 42.0) << "s32: 20.8 / 0.5 rounded";
  const double beat0 = b.driver->raw(b.index("plc_beat"));
  b.cycles(1);
  EXPECT_EQ(b.driver->raw(b.index("plc_beat")), beat0 + 1.0) << "edmplc's heartbeat counts";

  // FAULT: the generator off; the velocity (safe_in: estop) still the programs'.
  rt::Alarm fault;
  fault.code = rt::AlarmCode::kIoFault;
  fault.source = "test";
  fault.text = "a drive fault (test)";
  b.rt->machine().raise(fault);
  b.cycles(1);
  ASSERT_EQ(b.rt->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(b.driver->raw(b.index("gen_on")), 0.0);
  EXPECT_EQ(b.driver->raw(b.index("vz_cmd")), -1.5);
  ASSERT_EQ(b.rt->machine().command(rt::MachineCommand::kEstop), rt::CommandResult::kOk);
  b.cycles(1);
  EXPECT_EQ(b.driver->raw(b.index("vz_cmd")), 0.0) << "ESTOP: the axes held";
}

// The HAL side beats for 50 cycles and then stops: alarm 121 and FAULT exactly stale_cycles + 1
// cycles after its last beat, the generator off in that same cycle; a new beat clears the alarm,
// and a reset brings READY back.
TEST(HalDriverDetached, AStoppedHeartbeatIsAlarm121AndTheSafeStateWithinStaleCyclesPlusOne) {
  Built b(machine("edmtest", kPins, kWires, "stale_cycles: 5"), false);
  const std::size_t beat = b.index("beat");
  for (int i = 1; i <= 50; ++i) {
    b.driver->set_raw(beat, static_cast<double>(i));
    b.cycles(1);
  }
  ASSERT_EQ(b.rt->machine().state(), rt::MachineState::kReady);
  ASSERT_EQ(b.driver->raw(b.index("gen_on")), 1.0);
  int cycles_to_fault = 0;
  while (b.rt->machine().state() == rt::MachineState::kReady && cycles_to_fault < 100) {
    b.cycles(1);
    ++cycles_to_fault;
    if (cycles_to_fault <= 5) {
      EXPECT_EQ(b.driver->raw(b.index("gen_on")), 1.0) << cycles_to_fault;
    }
  }
  EXPECT_EQ(cycles_to_fault, 6) << "stale_cycles 5: the 6th cycle without a beat";
  EXPECT_EQ(b.rt->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(b.rt->machine().last_cause(), rt::AlarmCode::kIoStale);
  EXPECT_TRUE(b.has_alarm(rt::AlarmCode::kIoStale));
  EXPECT_EQ(b.driver->raw(b.index("gen_on")), 0.0) << "generator off in the cycle of the alarm";
  b.driver->set_raw(beat, 51.0);
  b.cycles(1);
  EXPECT_FALSE(b.has_alarm(rt::AlarmCode::kIoStale)) << "beats again: cleared";
  ASSERT_EQ(b.rt->machine().command(rt::MachineCommand::kReset), rt::CommandResult::kOk);
  b.driver->set_raw(beat, 52.0);
  b.cycles(1);
  EXPECT_EQ(b.rt->machine().state(), rt::MachineState::kReady);
}

// Pacing: a cycle waits for the HAL side's next beat after its release, at most pace_wait. No beat:
// it waits pace_wait and goes on; a beat before the release is not the next one. A beat another
// thread writes 5 ms into the wait ends it (a 200 ms task and a 100 ms pace_wait: a loaded host's
// thread wake-ups, several ms here, stay inside the window).
TEST(HalDriverDetached, PacingWaitsForTheNextBeatAtMostPaceWait) {
  Built b(machine("edmtest", kPins, kWires, "pace_wait: 100ms, stale_cycles: 100", "200ms"), false);
  const std::size_t beat = b.index("beat");
  b.driver->set_raw(beat, 1.0);
  b.cycles(1);
  auto t0 = std::chrono::steady_clock::now();
  b.cycles(1);  // no beat comes: waits pace_wait
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));
  EXPECT_EQ(b.driver->paced_cycles(), 0u);
  b.driver->set_raw(beat, 2.0);
  t0 = std::chrono::steady_clock::now();
  b.cycles(1);  // a beat before the release is not the next one: waits again
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(100));
  EXPECT_EQ(b.driver->paced_cycles(), 0u);
  std::atomic<bool> go{false};
  std::thread hal_side([&] {
    while (!go.load()) {
      std::this_thread::yield();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the HAL side's step time
    b.driver->set_raw(beat, 3.0);
  });
  go.store(true);
  t0 = std::chrono::steady_clock::now();
  b.cycles(1);
  const auto waited = std::chrono::steady_clock::now() - t0;
  hal_side.join();
  EXPECT_EQ(b.driver->paced_cycles(), 1u) << "the wait ended on the beat";
  EXPECT_LT(waited, std::chrono::milliseconds(100));
}

// Without a HAL session, an attached build refuses at the config (edmplc: exit 2).
TEST(HalDriverAttached, HalNotRunningIsAConfigErrorAtTheComponent) {
  if (hal_running()) GTEST_SKIP() << "a HAL session is running on this machine";
  const std::string path = (fs::temp_directory_path() / "edm-hal-not-running.yaml").string();
  { std::ofstream(path) << machine("edmtest", kPins, kWires); }
  apps::SpawnOptions o;
  o.err = apps::Stream::kStdout;
  const apps::RunResult r = apps::run({EDM_EDMPLC_PATH, "--config", path, "--run-for", "1s"}, o,
                                      std::chrono::seconds(30));
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(path + ":6:25: I/O driver 'hal': component HAL is not running"),
            std::string::npos)
      << r.out;
  fs::remove(path);
}

class HalDriverAttachedTest : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ = std::make_unique<HalSession>(EDM_TEST_DATA_DIR "/hal/threads.hal");
    ASSERT_TRUE(session_->ok()) << session_->error();
  }
  void TearDown() override { session_.reset(); }
  std::unique_ptr<HalSession> session_;
};

TEST_F(HalDriverAttachedTest, ValuesGoThroughHalsSharedMemoryBothWays) {
  const std::string pins =
      "      - {name: x_mm, hal: x-pos-fb, type: float, direction: in, scale: 0.001, "
      "signal: t-x}\n"
      "      - {name: n_short, type: u32, direction: in, counter: true, signal: t-n}\n"
      "      - {name: gen_on, type: bit, direction: out, safe: false, signal: t-gen}\n"
      "      - {name: vz_cmd, type: float, direction: out, scale: 2, signal: t-vz}\n";
  Built b(machine("edmtest", pins, "      io.gen_on: true\n      io.vz_cmd: -3.0\n"), true);
  ASSERT_TRUE(b.driver->attached());
  ASSERT_TRUE(session_->halcmd({"sets", "t-x", "2500"}));
  ASSERT_TRUE(session_->halcmd({"sets", "t-n", "100"}));
  b.cycles(1);
  EXPECT_DOUBLE_EQ(b.read("io.x_mm"), 2.5);
  ASSERT_TRUE(session_->halcmd({"sets", "t-n", "117"}));
  b.cycles(1);
  EXPECT_EQ(b.read("io.n_short"), 17.0);
  EXPECT_EQ(session_->gets("t-gen").value_or("?"), "TRUE");
  EXPECT_EQ(std::stod(session_->gets("t-vz").value_or("nan")), -1.5);
  const auto pin = session_->halcmd({"-s", "show", "pin", "edmtest.x-pos-fb"});
  ASSERT_TRUE(pin);
  EXPECT_NE(pin->find("float"), std::string::npos) << *pin;
  EXPECT_NE(pin->find("IN"), std::string::npos) << *pin;
}

TEST_F(HalDriverAttachedTest, AComponentNameInUseIsAConfigError) {
  Component other;
  ASSERT_EQ(other.open("edmtaken"), "");
  try {
    Built b(machine("edmtaken", kPins, kWires), true);
    ADD_FAILURE() << "built with a component name in use";
  } catch (const rt::ConfigError& e) {
    const rt::Diagnostic& d = e.diagnostics().front();
    EXPECT_EQ(d.loc.line, 6) << d.message;
    EXPECT_EQ(d.loc.col, 25) << d.message;
    EXPECT_NE(d.message.find("component HAL refused component 'edmtaken': the name is in use"),
              std::string::npos)
        << d.message;
  }
}

TEST_F(HalDriverAttachedTest, ALinkHalRefusesIsAConfigErrorNamingThePin) {
  ASSERT_TRUE(session_->halcmd({"newsig", "t-float", "float"}));
  const std::string pins = "      - {name: gen_on, type: bit, direction: out, signal: t-float}\n";
  try {
    Built b(machine("edmlink", pins), true);
    ADD_FAILURE() << "a bit pin was linked to a float signal";
  } catch (const rt::ConfigError& e) {
    const std::string m = e.diagnostics().front().message;
    EXPECT_NE(m.find("pins[0] (io.gen_on): HAL pin 'edmlink.gen-on' cannot be linked to signal "
                     "'t-float'"),
              std::string::npos)
        << m;
  }
  // The refused component is gone: the name can be used again.
  EXPECT_FALSE(session_->halcmd({"-s", "show", "pin", "edmlink"}).value_or("").find("gen-on") !=
               std::string::npos);
}

}  // namespace
}  // namespace edm::hal
