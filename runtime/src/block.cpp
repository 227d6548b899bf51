#include "edm/runtime/block.hpp"

namespace edm::rt {

std::vector<ParamError> Block::stage_param(std::size_t /*index*/, const ParamValue& /*v*/) {
  return {{"", "this block has no writable parameters"}};
}

void Block::apply_param(std::size_t /*index*/, const ParamValue& /*v*/) noexcept {}

ParamValue Block::read_param(std::size_t /*index*/) const { return {}; }

}  // namespace edm::rt
