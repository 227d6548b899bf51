#pragma once
// The one list of built-in C++ PROGRAM types (explicit registration, STYLE.md 3).

#include "edm/runtime/type_registry.hpp"

namespace edm::programs {

/// Adds every C++ PROGRAM type of this library to r ("DeepHoleDrill"). Non-RT; call once at
/// start-up, next to blocks::register_builtin_blocks().
void register_builtin_programs(rt::BlockRegistry& r);

}  // namespace edm::programs
