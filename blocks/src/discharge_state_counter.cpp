#include "edm/blocks/discharge_state_counter.hpp"

#include <bit>

namespace edm::blocks {
namespace {

// Centred Bresenham: number of class-A pulses among the first i of `total` when `a` of them are
// class A. E(0) = 0, E(total) = a, non-decreasing by at most 1 per step.
constexpr std::int64_t spread(std::int64_t i, std::int64_t a, std::int64_t total) noexcept {
  return (2 * i * a + total) / (2 * total);
}

}  // namespace

void DischargeStateCounter::activate() noexcept {
  reg_[0] = reg_[1] = reg_[2] = 0;
  since_latch_ = 0;
  open_count_.set(0);
  normal_count_.set(0);
  short_count_.set(0);
  latches_.set(0);
  data_ready_.set(false);
}

DischargeStateCounter::PulseClass DischargeStateCounter::pulse_class(std::int64_t i, std::int64_t o,
                                                                     std::int64_t n,
                                                                     std::int64_t s) noexcept {
  const std::int64_t total = o + n + s;
  const std::int64_t opens_before = spread(i, o, total);
  if (spread(i + 1, o, total) > opens_before) {
    return PulseClass::kOpen;
  }
  const std::int64_t r = i - opens_before;  // index among the non-open pulses
  const std::int64_t rest = n + s;          // > 0 here, since this pulse is not open
  return spread(r + 1, n, rest) > spread(r, n, rest) ? PulseClass::kNormal : PulseClass::kShort;
}

DischargeStateCounter::Regs DischargeStateCounter::shifted(const Regs& before, std::int64_t j,
                                                           std::int64_t o, std::int64_t n,
                                                           std::int64_t s) noexcept {
  Regs out;
  const std::int64_t shift = j + 1;  // pulses shifted in
  if (shift < kBits) {
    for (int c = 0; c < 3; ++c) {
      out.r[c] = static_cast<std::uint32_t>(std::uint64_t{before.r[c]} << shift);
    }
  }
  const std::int64_t newest = shift < kBits ? shift : kBits;
  for (std::int64_t k = 0; k < newest; ++k) {  // bit k holds pulse j − k
    const auto c = static_cast<int>(pulse_class(j - k, o, n, s));
    out.r[c] |= std::uint32_t{1} << k;
  }
  return out;
}

rt::BlockStatus DischargeStateCounter::update(const rt::CycleContext& /*ctx*/) noexcept {
  const std::int64_t in[5] = {n_open_.get(), n_normal_.get(), n_short_.get(),
                              n_transient_arc_.get(), n_stable_arc_.get()};
  for (const std::int64_t x : in) {
    if (x < 0 || x > kMaxCount) {
      return rt::BlockStatus::kFault;
    }
  }
  const std::int64_t m = params_.interval;
  if (m < 1) {
    return rt::BlockStatus::kFault;  // parameters that bypassed validate()
  }
  const std::int64_t arcs = in[3] + in[4];
  const std::int64_t o = in[0];
  const std::int64_t n = in[1] + (params_.arcs_as_short ? 0 : arcs);
  const std::int64_t s = in[2] + (params_.arcs_as_short ? arcs : 0);
  const std::int64_t total = o + n + s;
  if (total == 0) {
    latches_.set(0);
    data_ready_.set(false);
    return rt::BlockStatus::kOk;
  }

  const Regs before{{reg_[0], reg_[1], reg_[2]}};
  // Latches fall after the pulses where since_latch_ + j + 1 is a multiple of m.
  const std::int64_t reach = since_latch_ + total;
  const std::int64_t latches = reach / m;
  if (latches > 0) {
    const std::int64_t last = total - 1 - reach % m;
    const Regs at = shifted(before, last, o, n, s);
    open_count_.set(std::popcount(at.r[0]));
    normal_count_.set(std::popcount(at.r[1]));
    short_count_.set(std::popcount(at.r[2]));
  }
  latches_.set(latches);
  data_ready_.set(latches > 0);
  since_latch_ = reach % m;

  const Regs after = shifted(before, total - 1, o, n, s);
  for (int c = 0; c < 3; ++c) {
    reg_[c] = after.r[c];
  }
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
