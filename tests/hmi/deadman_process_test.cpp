// Issue 21 acceptance, the dead-man: `edmhmi jog X --velocity V` keeps a continuous jog alive by
// sending it again; when that edmhmi is killed (SIGKILL: no jog.stop, no goodbye) the runtime
// stops the axis within its dead-man time. A real edmplc on drill-sim, its virtual clock paced
// to wall time (1x) so that edmhmi's refresh period and the runtime's dead-man share one time base.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>

#include "process_fixture.hpp"

namespace edm::hmi::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class DeadMan : public EdmhmiProcessTest {
 protected:
  void start_paced_plc() {
    for (int attempt = 0; attempt < 3; ++attempt) {
      port_ = free_port();
      plc_ = std::make_unique<Proc>(
          std::vector<std::string>{EDM_EDMPLC_PATH, "--config", kDrillSim, "--clock", "virtual",
                                   "--speed", "1", "--bridge-port", std::to_string(port_)},
          dir_.file("edmplc.out"), dir_.file("edmplc.err"));
      const bool up = poll_until(
          [&] {
            if (plc_->poll()) return true;
            if ((plc_->out() + plc_->err()).find("bridge: listening on") == std::string::npos) {
              return false;
            }
            try {
              client_.connect(options());
              return true;
            } catch (const edm::bridge::ClientError&) {
              return false;
            }
          },
          20s, 25ms);
      if (up && !plc_->poll()) return;
      if (plc_->poll() && (plc_->out() + plc_->err()).find("in use") != std::string::npos) {
        continue;
      }
      FAIL() << "edmplc did not come up\n" << plc_->out() << plc_->err();
    }
  }
  edm::bridge::ClientOptions options() const {
    edm::bridge::ClientOptions o;
    o.port = static_cast<std::uint16_t>(port_);
    o.timeout = 5000ms;
    return o;
  }
  double x() {
    const auto r = client_.request("var.read", {{"names", {"io.x_mm"}}});
    EXPECT_TRUE(r.ok) << r.body;
    return r.body["values"]["io.x_mm"].get<double>();
  }
  edm::bridge::Json manual() {
    const auto r = client_.request("manual.status");
    EXPECT_TRUE(r.ok) << r.body;
    return r.body;
  }
  edm::bridge::Client client_;
};

TEST_F(DeadMan, AJogWhoseHmiIsKilledStopsWithinTheDeadManTime) {
  start_paced_plc();
  const double deadman_s =
      client_.request("machine.info").body["manual"]["deadman_ms"].get<double>() / 1e3;
  Proc& jog = spawn({"jog", "X", "--velocity", "2"});
  // Moving: the position grows (observed, with a deadline).
  const double x0 = x();
  ASSERT_TRUE(poll_until([&] { return x() > x0 + 0.2; }, 10s, 20ms))
      << jog.out() << jog.err() << plc_->err();
  // Still moving after several dead-man periods: edmhmi refreshes it.
  const double x1 = x();
  ASSERT_TRUE(poll_until([&] { return x() > x1 + 2.0 * deadman_s; }, 10s, 20ms));
  EXPECT_TRUE(manual()["busy"].get<bool>());

  jog.signal(SIGKILL);
  const auto killed = Clock::now();
  // The machine's own time at the kill (its clock is paced to wall time, but a loaded machine may
  // lag it: the dead-man is judged on the machine's clock).
  const double killed_t_s = client_.request("status").body["t_s"].get<double>();
  ASSERT_TRUE(jog.wait(5s).has_value());
  // The runtime ends the jog on its own: busy false, result dead-man.
  ASSERT_TRUE(poll_until([&] { return !manual()["busy"].get<bool>(); }, 10s, 10ms));
  const double after_s = std::chrono::duration<double>(Clock::now() - killed).count();
  const auto st = manual();
  EXPECT_EQ(st["result"]["error"], "dead-man: the jog was not refreshed in time") << st;
  // The axis stands still.
  const double xa = x();
  std::this_thread::sleep_for(300ms);  // an interval of wall (= machine) time to observe
  EXPECT_NEAR(x(), xa, 0.001);
  const double ended_after_s = st["result"]["t_s"].get<double>() - killed_t_s;
  std::printf(
      "edmhmi killed while jogging X at 2 mm/s: the jog ended %.0f ms of machine time "
      "later (%.0f ms of wall time; dead-man %.0f ms)\n",
      ended_after_s * 1e3, after_s * 1e3, deadman_s * 1e3);
  // The dead-man, one refresh period of edmhmi at most (deadman/3), the deceleration and the
  // settling in position, on the machine's clock.
  EXPECT_LE(ended_after_s, deadman_s + deadman_s / 3.0 + 0.2);
  EXPECT_LT(after_s, 10.0) << "never left moving";
}

}  // namespace
}  // namespace edm::hmi::test
