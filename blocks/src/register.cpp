#include "edm/blocks/register.hpp"

#include "edm/runtime/block.hpp"

namespace edm::blocks {

void register_builtin_blocks(rt::BlockRegistry& r) { (void)r; }

}  // namespace edm::blocks
