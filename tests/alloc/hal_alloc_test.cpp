// Zero allocations on the cycle thread with the hal driver: config/machines/drill-hal.yaml built
// with the driver detached (its pins in the driver's own memory, read and written through the
// same slots as HAL's shared memory, docs/hal.md), the HAL side's heartbeat and encoder played
// between cycles. Idle, a started job, and the heartbeat stopping (alarm 121, the safe state):
// every cycle counted.

#ifdef EDM_HAVE_HAL
#include <gtest/gtest.h>

#include <array>

#include "alloc/alloc_counter.hpp"
#include "alloc/drill_job.hpp"
#include "edm/blocks/register.hpp"
#include "edm/hal/driver.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/runtime.hpp"
#include "support/files.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

TEST(AllocationsHal, NoneInsideCyclesIdleInAJobAndWhenTheHeartbeatStops) {
  rt::BlockRegistry blocks;
  blocks::register_builtin_blocks(blocks);
  programs::register_builtin_programs(blocks);
  rt::DriverRegistry drivers;
  hal::register_hal_driver(drivers, /*attach=*/false);
  const std::string path = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-hal.yaml";
  auto r = rt::Runtime::build(rt::parse_config_text(read_file(path), path), blocks, drivers);
  r->machine().command(rt::MachineCommand::kPowerOn);
  auto& d = dynamic_cast<hal::HalDriver&>(r->driver());
  std::size_t beat = 0;
  std::size_t electrode = 0;
  std::array<std::size_t, 3> pos{};
  std::array<std::size_t, 3> vel{};
  const auto& map = d.pin_map();
  for (std::size_t i = 0; i < map.size(); ++i) {
    if (map[i].name == "hal_heartbeat") beat = i;
    if (map[i].name == "electrode_mm") electrode = i;
    for (std::size_t a = 0; a < 3; ++a) {
      const std::string axis(1, "xyz"[a]);
      if (map[i].name == axis + "_mm") pos[a] = i;
      if (map[i].name == "v" + axis + "_cmd") vel[a] = i;
    }
  }
  d.set_raw(pos[2], 5.0);
  d.set_raw(electrode, 300.0);  // edm-sim-hal's truth.electrode-mm: a new electrode
  rt::VirtualClock clock;
  std::int64_t k = 0;
  std::uint32_t beats = 0;
  const auto run = [&](int n, bool beating) {
    std::size_t total = 0;
    for (int i = 0; i < n; ++i, ++k) {
      if (beating) {  // the HAL side, between cycles: the beat, and drives that follow
        d.set_raw(beat, ++beats);
        for (std::size_t a = 0; a < 3; ++a) {
          d.set_raw(pos[a], d.raw(pos[a]) + d.raw(vel[a]) * 0.001);
        }
      }
      const rt::TimePoint release{1ms * k};
      clock.advance_to(release);
      total += allocations_in([&] {
        r->tasks()[0]->run_cycle(release, clock);
        if (k % 10 == 0) r->tasks()[1]->run_cycle(release, clock);
      });
    }
    return total;
  };
  EXPECT_EQ(run(300, true), 0u);
  ASSERT_EQ(r->machine().state(), rt::MachineState::kReady);
  EXPECT_EQ(r->variables().read("io.hal_ok"), 1.0);
  ASSERT_EQ(r->job().load(drill_job()), rt::LoadResult::kOk);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  EXPECT_EQ(run(200, true), 0u);
  EXPECT_EQ(r->machine().state(), rt::MachineState::kRunning);
  EXPECT_EQ(run(100, false), 0u) << "the heartbeat stops: alarm 121, the safe state";
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(r->machine().last_cause(), rt::AlarmCode::kIoStale);
  EXPECT_EQ(r->variables().read("io.hal_ok"), 0.0);
  EXPECT_EQ(r->variables().read("io.gen_on"), 0.0);
}

}  // namespace
}  // namespace edm::test
#endif
