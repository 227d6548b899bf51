#pragma once
// TdDetector: the mean ignition delay Td and the open/short ratios from the per-cycle pulse
// counters of the generator's FPGA (or the simulator's io.td_sum_ns, io.td_count, io.n_*).
//
//   total(k)    = n_total(k) if n_total(k) > 0, else td_count(k) + n_open(k) + n_short(k)
//   td_raw_us   = (td_sum_ns(k) + n_short(k)·Ts) / (td_count(k) + n_short(k)) / 1000   this cycle
//   td_us       = (Σ td_sum_ns + Σ n_short·Ts) / (Σ td_count + Σ n_short) / 1000
//                                                                   over the last `window` cycles
//   open_ratio  = Σ n_open / Σ total,  short_ratio = Σ n_short / Σ total   (same window)
//   valid       = Σ td_count + Σ n_short > 0   (an ignited or a shorted pulse in the window)
//   cycle_short_ratio = n_short(k) / total(k)  this cycle alone (0 without pulses): a short
//               shorter than the window reads here at once, while short_ratio climbs 1/window a
//               cycle (DESIGN §11: a cycle whose own pulses are all shorted reads short)
// Gap truth (seed 004): the gap feedback reads the full applied voltage on an open gap and about
// zero on a contact. A short is therefore a pulse whose ignition delay is Ts = short_td_us (0 by
// default: breakdown at once), pooled with the ignited pulses: a window of shorts reads Td ≈ 0,
// far below any Tdr, and the P law backs the electrode off at Kg·Tdr. (Counting only ignited
// pulses, as before, made a short-only window "not valid", and the drill then crept DOWN into the
// short.) Open pulses carry no delay measurement: a window of only opens is not valid (the gap is
// open; the consumer feeds at its idle speed).
//
// Pooling the sums (not averaging the per-cycle means) weighs every pulse equally, so a cycle
// with 3 pulses does not count as much as one with 300. The sums are exact 64-bit integers kept
// with a ring of `window` cycles: no drift, no O(window) work per cycle.
// Empty window (no ignited pulse, or no pulse at all for the ratios): nothing is divided; with
// hold_when_empty the outputs keep their last values, otherwise td_us/td_raw_us = empty_td_us
// and the ratios = 0. valid is false either way.
//
// `window` sizes the ring, allocated once in configure(); it cannot change at run time.
// A negative or absurdly large counter, or an n_total smaller than td_count or n_open + n_short,
// is a broken signal: the cycle is not stored, the outputs are held and update() returns kFault.
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins (see
// pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/blocks/window_ring.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct TdDetectorParams {
  static constexpr std::int64_t kMaxWindow = 65536;

  std::int64_t window{8};      // cycles pooled, 1..kMaxWindow (load time only)
  bool hold_when_empty{true};  // empty window: hold the last td_us (else output empty_td_us)
  double empty_td_us{0.0};  // [µs] ≥ 0: td_us after activate(), and when empty and not holding
  double short_td_us{0.0};  // [µs] ≥ 0: the ignition delay a shorted pulse counts with

  void visit(rt::ParamVisitor& v) {
    v.param("window", window,
            rt::load_time({"cycles", "number of cycles pooled",
                           rt::closed(1.0, static_cast<double>(kMaxWindow))}));
    v.param(
        "hold_when_empty", hold_when_empty,
        {"", "with no ignited pulse in the window keep the last td_us (else output empty_td_us)"});
    v.param(
        "empty_td_us", empty_td_us,
        {"us", "td_us after activation, and with an empty window when not holding", ranges::kTdUs});
    v.param("short_td_us", short_td_us,
            {"us", "ignition delay a shorted pulse counts with (gap feedback ~ 0)", ranges::kTdUs});
  }
};

class TdDetector final : public rt::BlockWithParams<TdDetectorParams> {
 public:
  /// Per-cycle counters above this are treated as a broken signal (keeps the window sums far
  /// from int64 overflow: kMaxWindow · kMaxCount < 2^63).
  static constexpr std::int64_t kMaxCount = std::int64_t{1} << 46;
  /// Non-RT. Allocates the ring (window cycles).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Empties the window: td_us = td_raw_us = empty_td_us, ratios 0, valid false.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (nothing stored, outputs held) on inconsistent counters.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  struct Counts {
    std::int64_t td_sum_ns{0};
    std::int64_t td_count{0};
    std::int64_t n_open{0};
    std::int64_t n_short{0};
    std::int64_t n_total{0};
  };

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<std::int64_t> td_sum_ns{pins_, "td_sum_ns", "ns"};
  rt::Input<std::int64_t> td_count{pins_, "td_count"};
  rt::Input<std::int64_t> n_open{pins_, "n_open"};
  rt::Input<std::int64_t> n_short{pins_, "n_short"};
  rt::Input<std::int64_t> n_total{pins_, "n_total"};
  rt::Output<double> td_us{pins_, "td_us", "us"};
  rt::Output<double> td_raw_us{pins_, "td_raw_us", "us"};
  rt::Output<double> open_ratio{pins_, "open_ratio", "1"};
  rt::Output<double> short_ratio{pins_, "short_ratio", "1"};
  rt::Output<bool> valid{pins_, "valid"};
  rt::Output<double> cycle_short_ratio{pins_, "cycle_short_ratio", "1"};

 private:
  WindowRing<Counts> window_;  // allocated in configure(); its capacity is the window in use
  Counts sum_;                 // sums over the ring
};

}  // namespace edm::blocks
