// edm-bench-hal (`./edm bench hal`, docs/benchmarks.md "HAL latency"): the round trip from a HAL
// output to the edmplc cycle that sees it and back. This process is the HAL side: component
// `edm-lat` with `stamp` and `beat` (u32 out) and `echo` (u32 in), on its own 1 ms paced loop as
// edm-sim-hal is. edmplc runs a config whose program wires io.echo from io.stamp
// (examples/hal/latency-echo*.yaml). Each sample: stamp ← n with the step's beat, then a spin
// until echo = n; the time between is edmplc's wait for its next input latch plus its cycle up to
// the output latch (this side sees the echo at once: it spins). Run inside a HAL session.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/apps/subprocess.hpp"
#include "edm/hal/component.hpp"

namespace {

using Ns = std::chrono::nanoseconds;

Ns monotonic() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::chrono::seconds(ts.tv_sec) + Ns(ts.tv_nsec);
}

void sleep_until(Ns t) {
  const timespec ts{static_cast<time_t>(t.count() / 1000000000),
                    static_cast<long>(t.count() % 1000000000)};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

double us(Ns d) { return static_cast<double>(d.count()) / 1000.0; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"HAL ↔ edmplc round-trip latency (docs/benchmarks.md)", "edm-bench-hal"};
  std::string edmplc;
  std::string config;
  int samples = 2000;
  app.add_option("--edmplc", edmplc, "the edmplc binary")->required();
  app.add_option("--config", config, "its config (examples/hal/latency-echo*.yaml)")->required();
  app.add_option("--samples", samples, "round trips to time")->check(CLI::Range(10, 1000000));
  if (const auto code = edm::apps::parse(app, argc, argv, "edm-bench-hal --edmplc P --config C")) {
    return *code;
  }
  edm::hal::Component comp;
  edm::hal::PinSlot stamp, beat, echo;
  std::string e = comp.open("edm-lat");
  if (e.empty()) e = comp.add_pin("stamp", edm::hal::HalType::kU32, edm::hal::HalDir::kOut, stamp);
  if (e.empty()) e = comp.add_pin("beat", edm::hal::HalType::kU32, edm::hal::HalDir::kOut, beat);
  if (e.empty()) e = comp.add_pin("echo", edm::hal::HalType::kU32, edm::hal::HalDir::kIn, echo);
  if (e.empty()) e = comp.link("stamp", "lat-stamp", edm::hal::HalType::kU32);
  if (e.empty()) e = comp.link("beat", "lat-beat", edm::hal::HalType::kU32);
  if (e.empty()) e = comp.link("echo", "lat-echo", edm::hal::HalType::kU32);
  if (e.empty()) e = comp.ready();
  if (!e.empty()) {
    std::fprintf(stderr, "edm-bench-hal: %s\n", e.c_str());
    return 2;
  }
  edm::apps::SpawnOptions o;
  o.out = edm::apps::Stream::kNull;
  o.err = edm::apps::Stream::kInherit;  // its log: the pacing statistics at the end
  edm::apps::Process plc({edmplc, "--config", config, "--bridge-port", "0"}, o);
  if (!plc.started()) {
    std::fprintf(stderr, "edm-bench-hal: %s\n", plc.error().c_str());
    return 1;
  }
  const Ns period = std::chrono::milliseconds(1);
  Ns next = monotonic();
  std::uint32_t beats = 0;
  std::uint32_t n = 1;
  std::vector<Ns> rtt;
  rtt.reserve(static_cast<std::size_t>(samples));
  int lost = 0;
  bool up = false;
  const Ns start = monotonic();
  for (int step = 0; static_cast<int>(rtt.size()) < samples; ++step) {
    next += period;
    sleep_until(next);
    if (plc.poll()) {
      std::fprintf(stderr, "edm-bench-hal: edmplc ended (%s)\n", plc.describe().c_str());
      return 1;
    }
    const bool sample = step % 4 == 0;
    const Ns t0 = monotonic();  // before the write: an echo can come back within the next read
    if (sample) edm::hal::pin_write_u32(stamp, ++n);
    edm::hal::pin_write_u32(beat, ++beats);  // the step is complete
    if (!sample) continue;
    Ns t1 = monotonic();
    while (edm::hal::pin_read_u32(echo) != n &&
           (t1 = monotonic()) - t0 < std::chrono::milliseconds(5)) {
    }
    if (edm::hal::pin_read_u32(echo) != n) {
      if (up) ++lost;
      if (!up && monotonic() - start > std::chrono::seconds(30)) {
        std::fprintf(stderr, "edm-bench-hal: no echo from edmplc in 30 s\n");
        return 1;
      }
      continue;
    }
    if (!up) {
      up = true;  // the first echo: edmplc runs; the next 200 steps settle
      step = -200;
      continue;
    }
    if (step > 0) rtt.push_back(t1 - t0);
  }
  plc.stop();
  std::sort(rtt.begin(), rtt.end());
  const auto q = [&](double f) {
    return rtt[std::min(rtt.size() - 1,
                        static_cast<std::size_t>(f * static_cast<double>(rtt.size())))];
  };
  std::printf("config %s\nround trips %zu (lost %d)\n", config.c_str(), rtt.size(), lost);
  std::printf(
      "HAL stamp -> edmplc cycle -> HAL echo, us: min %.1f  median %.1f  p90 %.1f  p99 %.1f"
      "  max %.1f\n",
      us(rtt.front()), us(q(0.5)), us(q(0.9)), us(q(0.99)), us(rtt.back()));
  return 0;
}
