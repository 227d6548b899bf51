// edm-sim-hal: the EDM plant simulator as a LinuxCNC HAL userspace component, in its own process
// (docs/hal.md). Load it from a .hal file: `loadusr -Wn edm-sim edm-sim-hal --seed 1`.
//
// It steps the plant on its own paced loop — absolute 1 ms deadlines on CLOCK_MONOTONIC, the plant
// run to the wall time of each wakeup — not from a HAL thread: in LinuxCNC's uspace, a userspace
// component's code cannot run as a function of a HAL thread (those are rtapi_app's modules). A late
// wakeup only makes one step longer: the plant runs to the time it is (every pulse in between),
// and its counters are free-running, so edmplc loses nothing. Ends on SIGTERM/SIGINT (halcmd
// unloadusr, halrun's end).
#include <sys/mman.h>
#include <time.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <string>

#include "edm/apps/cli.hpp"
#include "edm/hal/sim_component.hpp"

namespace {

std::atomic<bool> g_stop{false};

void on_signal(int /*sig*/) { g_stop.store(true); }

std::chrono::nanoseconds monotonic() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The EDM plant simulator as a LinuxCNC HAL component (docs/hal.md)", "edm-sim-hal"};
  edm::hal::SimComponentOptions o;
  std::int64_t period_us = 1000;
  std::int64_t plc_timeout_ms = 50;
  bool no_wall_sparks = false;
  app.add_option("--name", o.name, "HAL component name (its pins are <name>.<pin>)")
      ->capture_default_str();
  app.add_option("--preset", o.preset, "simulator preset (drill, sink, wire)")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_option("--period-us", period_us, "plant step period, microseconds")
      ->check(CLI::Range(100, 100000))
      ->capture_default_str();
  app.add_option("--plc-timeout-ms", plc_timeout_ms,
                 "generator and drives fall safe when plc-heartbeat stops this long")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_flag("--no-wall-sparks", no_wall_sparks, "the tube's wall bins do not spark");
  if (const auto code = edm::apps::parse(app, argc, argv, "edm-sim-hal [--name N] [--seed S]")) {
    return *code;
  }
  o.wall_sparks = !no_wall_sparks;
  o.plc_timeout = std::chrono::milliseconds(plc_timeout_ms);

  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  std::string error;
  edm::hal::SimComponent sim(o, error);
  if (!error.empty()) {
    std::fprintf(stderr, "edm-sim-hal: %s\n", error.c_str());
    return 2;
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::fprintf(stderr, "edm-sim-hal: mlockall failed (memory may page)\n");
  }
  std::fprintf(stderr, "edm-sim-hal: component '%s' ready (preset %s, seed %llu, %lld us)\n",
               o.name.c_str(), o.preset.c_str(), static_cast<unsigned long long>(o.seed),
               static_cast<long long>(period_us));
  const auto period = std::chrono::microseconds(period_us);
  const auto origin = monotonic();
  auto next = origin;
  bool was_lost = false;
  while (!g_stop.load(std::memory_order_relaxed)) {
    next += period;
    const timespec ts{static_cast<time_t>(next.count() / 1000000000),
                      static_cast<long>(next.count() % 1000000000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    const auto now = monotonic();
    if (now - next > 100 * period) next = now;  // a long stall: no catch-up burst
    sim.step(now - origin);
    if (sim.plc_lost() != was_lost) {
      was_lost = sim.plc_lost();
      std::fprintf(stderr, "edm-sim-hal: plc-heartbeat %s\n",
                   was_lost ? "stopped: generator off, axes stopped" : "beats again");
    }
  }
  std::fprintf(stderr, "edm-sim-hal: stopped after %llu steps\n",
               static_cast<unsigned long long>(sim.steps()));
  return 0;
}
