#pragma once
// Pin sampler: one cycle's values of a fixed list of pins, as doubles (read_pin_as_double). The
// trace recorder (trace.hpp, `--trace-out`) and the bridge's trace tap (edm/bridge/trace_tap.hpp)
// both sample through it, so a pin reads the same in a CSV trace and in a streamed one.
//
// RT-safety: sample() is RT-safe (no allocation, no lock, noexcept). assign() is non-RT (it
// validates and may throw).
// Thread-safety: none of its own. sample() may run on the owning task's thread while nothing
// assigns; assign() must not overlap a sample() (the trace tap's handshake guarantees that, the
// recorder assigns before sampling starts).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "edm/runtime/pin.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

inline constexpr std::size_t kMaxTraceVarsPerTask = 32;

/// One cycle's values of one sampler. Trivially copyable: rings copy it as is.
struct TraceSample {
  TimePoint release{0};  // scheduled release time of the cycle, ns
  std::uint64_t cycle{0};
  std::uint32_t channel{0};
  std::uint32_t n{0};  // number of valid entries in v
  std::array<double, kMaxTraceVarsPerTask> v{};
};

class PinSampler {
 public:
  /// Non-RT. Replaces the pins (empty: none). Throws std::invalid_argument, and keeps the
  /// previous pins, if there are more than kMaxTraceVarsPerTask or one has no pin.
  void assign(std::span<const PinRef> pins);

  /// RT-safe. Reads every pin now: v[i] is pin i (bools as 0/1), n the pin count.
  [[nodiscard]] TraceSample sample(TimePoint release, std::uint64_t cycle,
                                   std::uint32_t channel = 0) const noexcept;

  [[nodiscard]] std::uint32_t size() const noexcept { return n_; }

 private:
  std::array<PinRef, kMaxTraceVarsPerTask> pins_{};
  std::uint32_t n_{0};
};

}  // namespace edm::rt
