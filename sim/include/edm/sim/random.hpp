#pragma once
// Counter-based random variates for the plant (PLANT-MODEL.md §6.6). A variate is a pure hash of
// (seed, stream, index), so pulse k draws the same numbers whatever the controller did before it
// (common random numbers across controllers), and nothing depends on call order.
//
// RT-safety: everything is constexpr/inline arithmetic: no allocation, no locks, no exceptions.
// Thread-safety: pure functions, safe from any thread.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace edm::sim {

/// One independent stream per use of randomness in a pulse, so adding a draw in one place does not
/// shift the numbers another place sees. Values are part of the log format: append only.
enum class Stream : std::uint64_t {
  kTd = 1,               // ignition delay quantile
  kArc = 2,              // arc yes/no
  kArcTd = 3,            // arc delay in U(0, 0.5 µs)
  kDebrisShort = 4,      // debris-bridge short yes/no
  kRemovalScatter = 5,   // crater volume scatter (normal, two uniforms per pulse)
  kSite = 6,             // discharge site when the wall bins compete (orbit)
  kWireBreak = 7,        // WEDM: the tolerated damage of the abnormal-discharge rupture hazard
  kShortEvent = 8,       // a short event (debris bridge, tube contact) starts at this pulse
  kShortEventKind = 9,   // which of the competing events it is
  kShortEventLife = 10,  // how long it lasts
  kRefSwitch = 11,       // reference switch trip points (normal, index 3 trip + axis)
  kTouch = 12,           // touch-sensing threshold (normal, index: contact event)
};

inline constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;

/// The SplitMix64 finaliser: a bijective 64-bit mixer with full avalanche.
constexpr std::uint64_t splitmix64_mix(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// Sequential SplitMix64, used to derive seeds (e.g. one per benchmark run). Not used per pulse.
class SplitMix64 {
 public:
  explicit constexpr SplitMix64(std::uint64_t seed) noexcept : state_(seed) {}
  constexpr std::uint64_t next() noexcept { return splitmix64_mix(state_ += kGolden); }

 private:
  std::uint64_t state_;
};

/// 64 random bits for (seed, stream, index): element `index` of the SplitMix64 sequence whose
/// start is derived from (seed, stream).
constexpr std::uint64_t hash_bits(std::uint64_t seed, Stream stream, std::uint64_t index) noexcept {
  const std::uint64_t key =
      splitmix64_mix(seed + kGolden * (static_cast<std::uint64_t>(stream) + 1));
  return splitmix64_mix(key + kGolden * (index + 1));
}

/// Uniform in the open interval (0, 1): 53 bits plus one half-ulp, so log(u) and log(1-u) are
/// always finite.
constexpr double uniform(std::uint64_t seed, Stream stream, std::uint64_t index) noexcept {
  return (static_cast<double>(hash_bits(seed, stream, index) >> 11) + 0.5) * 0x1.0p-53;
}

/// Standard normal from two keyed uniforms (Box–Muller, cosine branch); uses indices 2i, 2i+1.
inline double normal(std::uint64_t seed, Stream stream, std::uint64_t index) noexcept {
  const double u1 = uniform(seed, stream, 2 * index);
  const double u2 = uniform(seed, stream, 2 * index + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace edm::sim
