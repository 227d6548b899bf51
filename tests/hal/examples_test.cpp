// The example HAL files of examples/hal/ (docs/hal.md): each board's file with its hardware lines
// replaced by edm-hal-stub (the card's pin names) loads under halrun, its servo-thread heartbeat
// beats, its nets reach the card's pins, and edmplc with config/machines/drill-hal.yaml links
// every one of its pins to those signals (a type that disagrees would be exit 2) and runs 1 s with
// the heartbeat fresh (no alarm 121).

#include <gtest/gtest.h>

#include "hal/hal_session.hpp"

namespace edm::hal {
namespace {

using test::HalSession;
using test::poll_until;

struct Board {
  const char* file;     // examples/hal/<file>-sim.hal
  const char* vel_pin;  // the card's pin edm-x-vel-cmd must reach
  const char* gen_pin;  // the card's pin edm-gen-on must reach
};

void PrintTo(const Board& b, std::ostream* os) { *os << b.file; }

class HalExamples : public ::testing::TestWithParam<Board> {};

TEST_P(HalExamples, LoadsWithStandInsAndEdmplcLinksToItsSignals) {
  const Board& b = GetParam();
  HalSession hal(std::string("examples/hal/") + b.file + "-sim.hal");
  ASSERT_TRUE(hal.ok()) << hal.error();
  std::optional<std::string> first;
  ASSERT_TRUE(poll_until([&] { return (first = hal.gets("edm-heartbeat")).has_value(); },
                         std::chrono::seconds(20), std::chrono::milliseconds(50)))
      << hal.log();
  ASSERT_TRUE(
      poll_until([&] { return hal.gets("edm-heartbeat") != first; }, std::chrono::seconds(10)))
      << "the servo thread's heartbeat does not count\n"
      << hal.log();
  const auto vel = hal.halcmd({"-s", "show", "sig", "edm-x-vel-cmd"});
  ASSERT_TRUE(vel);
  EXPECT_NE(vel->find(b.vel_pin), std::string::npos) << *vel;
  const auto gen = hal.halcmd({"-s", "show", "sig", "edm-gen-on"});
  ASSERT_TRUE(gen);
  EXPECT_NE(gen->find(b.gen_pin), std::string::npos) << *gen;
  EXPECT_EQ(hal.log().find("rror"), std::string::npos) << hal.log();

  // No electrode sensor on these boards: drill-hal.yaml's electrode check reads the simulator's
  // truth signal, a HAL constant here: a new electrode's 300 mm (docs/hal.md says what a real
  // machine wires).
  ASSERT_TRUE(hal.halcmd({"loadrt", "constant"}));
  ASSERT_TRUE(hal.halcmd({"setp", "constant.0.value", "300"}));
  ASSERT_TRUE(hal.halcmd({"addf", "constant.0", "servo-thread"}));
  ASSERT_TRUE(hal.halcmd({"net", "edm-truth-electrode", "constant.0.out"}));
  apps::SpawnOptions o;
  o.err = apps::Stream::kStdout;
  o.set_env = hal.env();
  o.unset_env = {"EDM_STATE_DIR"};
  const apps::RunResult r =
      apps::run({EDM_EDMPLC_PATH, "--config", test::kSourceDir + "/config/machines/drill-hal.yaml",
                 "--bridge-port", "0", "--run-for", "1s"},
                o, std::chrono::seconds(60));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.find("cannot be linked"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("ALARM 121"), std::string::npos) << r.out;
}

INSTANTIATE_TEST_SUITE_P(
    Boards, HalExamples,
    ::testing::Values(Board{"mesa-7i96s", "hm2_7i96s.0.stepgen.00.velocity-cmd",
                            "hm2_7i96s.0.ssr.00.out-01"},
                      Board{"mesa-7i76e", "hm2_7i76e.0.stepgen.00.velocity-cmd",
                            "hm2_7i76e.0.7i76.0.0.output-01"},
                      Board{"parport", "stepgen.0.velocity-cmd", "parport.0.pin-09-out"}),
    [](const ::testing::TestParamInfo<Board>& p) {
      std::string n = p.param.file;
      for (char& c : n) {
        if (c == '-') c = '_';
      }
      return n;
    });

}  // namespace
}  // namespace edm::hal
