#include "edm/blocks/discharge_state_counter.hpp"

#include <bit>

namespace edm::blocks {
namespace {

constexpr std::int64_t kMask32 = 0xFFFF'FFFFLL;

}  // namespace

void DischargeStateCounter::activate() noexcept {
  reg_[0] = reg_[1] = reg_[2] = 0;
  seen_ = 0;
  since_latch_ = 0;
  open_count_.set(0);
  normal_count_.set(0);
  short_count_.set(0);
  data_ready_.set(false);
}

rt::BlockStatus DischargeStateCounter::update(const rt::CycleContext& /*ctx*/) noexcept {
  const std::int64_t in[5] = {n_open_.get(), n_normal_.get(), n_short_.get(),
                              n_transient_arc_.get(), n_stable_arc_.get()};
  std::int64_t pulses = 0;
  for (const std::int64_t x : in) {
    if (x < 0 || x > kMaxCount) {
      return fault("a pulse counter out of range", static_cast<double>(x));
    }
    pulses += x;
  }
  const std::int64_t h[3] = {hist_open_.get(), hist_short_.get(), hist_arc_.get()};
  for (const std::int64_t x : h) {
    if (x < 0 || x > kMask32) {
      return fault("a pulse-history word out of range", static_cast<double>(x));
    }
  }
  const auto open = static_cast<std::uint32_t>(h[0]);
  const auto shorts = static_cast<std::uint32_t>(h[1]);
  const auto arcs = static_cast<std::uint32_t>(h[2]);
  if ((open & shorts) != 0 || (open & arcs) != 0 || (shorts & arcs) != 0) {
    return fault(
        "a pulse in two classes at once (the history words overlap)");  // a pulse has exactly one
                                                                        // class
  }
  const std::int64_t m = params_.interval;
  if (m < 1) {
    return fault("interval below 1 (parameters that bypassed validation)",
                 static_cast<double>(m));  // parameters that bypassed validate()
  }
  if (pulses == 0) {
    data_ready_.set(false);
    return rt::BlockStatus::kOk;
  }

  seen_ = seen_ + pulses < kBits ? seen_ + pulses : kBits;
  const std::uint32_t live =
      seen_ >= kBits ? 0xFFFF'FFFFU : (std::uint32_t{1} << static_cast<unsigned>(seen_)) - 1U;
  const std::uint32_t as_short = params_.arcs_as_short ? arcs : 0U;
  reg_[0] = open & live;
  reg_[2] = (shorts | as_short) & live;
  reg_[1] = ~(open | shorts | as_short) & live;

  since_latch_ += pulses;
  const bool latch = since_latch_ >= m;
  if (latch) {
    open_count_.set(std::popcount(reg_[0]));
    normal_count_.set(std::popcount(reg_[1]));
    short_count_.set(std::popcount(reg_[2]));
    since_latch_ = 0;
  }
  data_ready_.set(latch);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
