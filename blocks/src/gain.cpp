#include "edm/blocks/gain.hpp"

#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> GainParams::validate() const {
  std::vector<rt::ParamError> errs;
  require_finite(errs, "k", k);
  require_finite(errs, "offset", offset);
  return errs;
}

void Gain::visit_pins(rt::PinVisitor& v) {
  v.input("in", in_);
  v.output("out", out_);
}

rt::BlockStatus Gain::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double y = params_.k * in_.get() + params_.offset;
  // One check covers a non-finite input and an overflowing product.
  if (!std::isfinite(y)) {
    return rt::BlockStatus::kFault;
  }
  out_.set(y);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
