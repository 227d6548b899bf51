#pragma once
// The one list of built-in block types (explicit registration, STYLE.md 3).

#include "edm/runtime/type_registry.hpp"

namespace edm::blocks {

/// Adds every block type of this library to r. Non-RT; call once at start-up.
void register_builtin_blocks(rt::BlockRegistry& r);

}  // namespace edm::blocks
