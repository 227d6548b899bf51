#include "edm/blocks/td_detector.hpp"

#include <algorithm>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {
namespace {

constexpr double kNsPerUs = 1000.0;

}  // namespace

std::vector<rt::ParamError> TdDetector::configure(const rt::BlockSetup& /*setup*/) {
  return configure_checked(params_, [this] {
    window_.allocate(static_cast<std::size_t>(params_.window));
    activate();
  });
}

void TdDetector::activate() noexcept {
  window_.clear();
  sum_ = {};
  td_us.set(params_.empty_td_us);
  td_raw_us.set(params_.empty_td_us);
  open_ratio.set(0.0);
  short_ratio.set(0.0);
  valid.set(false);
  cycle_short_ratio.set(0.0);
}

rt::BlockStatus TdDetector::update(const rt::CycleContext& /*ctx*/) noexcept {
  Counts c{td_sum_ns.get(), td_count.get(), n_open.get(), n_short.get(), n_total.get()};
  const auto in_range = [](std::int64_t x) noexcept { return x >= 0 && x <= kMaxCount; };
  if (window_.capacity() == 0 || !in_range(c.td_sum_ns) || !in_range(c.td_count) ||
      !in_range(c.n_open) || !in_range(c.n_short) || !in_range(c.n_total)) {
    return fault("a pulse counter out of range, or not configured",
                 static_cast<double>(c.n_total));  // ring empty: not configured
  }
  if (c.n_total == 0) {
    c.n_total = c.td_count + c.n_open + c.n_short;  // unwired: the classes add up to all pulses
  } else if (c.n_total < c.td_count || c.n_total < c.n_open + c.n_short) {
    return fault("the pulse counters disagree (a class above the total)",
                 static_cast<double>(c.n_total));  // a ratio above 1: the counters disagree
  }
  if (c.td_count == 0 && c.td_sum_ns != 0) {
    return fault("a delay sum without pulses",
                 static_cast<double>(c.td_sum_ns));  // a delay sum without pulses
  }

  cycle_short_ratio.set(
      c.n_total > 0 ? static_cast<double>(c.n_short) / static_cast<double>(c.n_total) : 0.0);
  const Counts old = window_.push(c);  // all 0 until the window is full
  sum_.td_sum_ns += c.td_sum_ns - old.td_sum_ns;
  sum_.td_count += c.td_count - old.td_count;
  sum_.n_open += c.n_open - old.n_open;
  sum_.n_short += c.n_short - old.n_short;
  sum_.n_total += c.n_total - old.n_total;

  const bool hold = params_.hold_when_empty;
  const double short_ns = params_.short_td_us * kNsPerUs;
  const auto mean_us = [short_ns](std::int64_t sum_ns, std::int64_t ignited, std::int64_t shorts) {
    return (static_cast<double>(sum_ns) + static_cast<double>(shorts) * short_ns) /
           static_cast<double>(ignited + shorts) / kNsPerUs;
  };
  if (c.td_count + c.n_short > 0) {
    td_raw_us.set(mean_us(c.td_sum_ns, c.td_count, c.n_short));
  } else if (!hold) {
    td_raw_us.set(params_.empty_td_us);
  }
  const bool valid_now = sum_.td_count + sum_.n_short > 0;
  if (valid_now) {
    td_us.set(mean_us(sum_.td_sum_ns, sum_.td_count, sum_.n_short));
  } else if (!hold) {
    td_us.set(params_.empty_td_us);
  }
  if (sum_.n_total > 0) {
    const auto total = static_cast<double>(sum_.n_total);
    open_ratio.set(static_cast<double>(sum_.n_open) / total);
    short_ratio.set(static_cast<double>(sum_.n_short) / total);
  } else if (!hold) {
    open_ratio.set(0.0);
    short_ratio.set(0.0);
  }
  valid.set(valid_now);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
