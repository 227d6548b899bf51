#include "edm/programs/register.hpp"

#include "edm/programs/deep_hole_drill.hpp"

namespace edm::programs {

void register_builtin_programs(rt::BlockRegistry& r) { r.add<DeepHoleDrill>("DeepHoleDrill"); }

}  // namespace edm::programs
