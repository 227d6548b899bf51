#include "edm/programs/register.hpp"

#include "edm/programs/deep_hole_drill.hpp"
#include "edm/programs/edm_job.hpp"
#include "edm/programs/wall_finish.hpp"

namespace edm::programs {

void register_builtin_programs(rt::BlockRegistry& r) {
  r.add<DeepHoleDrill>("DeepHoleDrill");
  r.add<EdmJob>("EdmJob", "job sequencer: runs the loaded part program (drill, finish, moves)");
  r.add<WallFinish>(
      "WallFinish",
      "seed 004 hole-wall finishing: positive polarity, orbit with eq. 20-21 radius growth");
}

}  // namespace edm::programs
