#include "edm/blocks/gain.hpp"

#include <cmath>

namespace edm::blocks {

rt::BlockStatus Gain::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double y = params_.k * in_.get() + params_.offset;
  // One check covers a non-finite input and an overflowing product.
  if (!std::isfinite(y)) {
    return fault("a non-finite output (input or k times input)", y);
  }
  out_.set(y);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
