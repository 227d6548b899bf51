#include "edm/runtime/pin_sampler.hpp"

#include <stdexcept>
#include <string>
#include <type_traits>

namespace edm::rt {

static_assert(std::is_trivially_copyable_v<TraceSample>, "trace samples are copied as bytes");

void PinSampler::assign(std::span<const PinRef> pins) {
  if (pins.size() > kMaxTraceVarsPerTask) {
    throw std::invalid_argument("pin sampler: " + std::to_string(pins.size()) + " pins; at most " +
                                std::to_string(kMaxTraceVarsPerTask));
  }
  for (std::size_t i = 0; i < pins.size(); ++i) {
    if (pins[i].pin == nullptr) {
      throw std::invalid_argument("pin sampler: pin " + std::to_string(i) + " is null");
    }
  }
  for (std::size_t i = 0; i < pins.size(); ++i) {
    pins_[i] = pins[i];
  }
  n_ = static_cast<std::uint32_t>(pins.size());
}

TraceSample PinSampler::sample(TimePoint release, std::uint64_t cycle,
                               std::uint32_t channel) const noexcept {
  TraceSample s;
  s.release = release;
  s.cycle = cycle;
  s.channel = channel;
  s.n = n_;
  for (std::uint32_t i = 0; i < n_; ++i) {
    s.v[i] = read_pin_as_double(pins_[i]);
  }
  return s;
}

}  // namespace edm::rt
