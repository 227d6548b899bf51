#pragma once
// The operator functions' ops (DESIGN §12, issue 21; docs/protocol.md "Operator functions"):
//   home, jog, jog.stop, touch, manual.status   → rt::ManualControl (the runtime's ManualMotion)
//   offset.get, offset.set                      → rt::WorkOffsets (retained)
//   cycle.start {slot, dry_run}                 → the checks before a start and StartOptions
// Server thread only.

#include <optional>
#include <string>

#include "edm/runtime/job.hpp"
#include "edm/runtime/manual.hpp"
#include "ops_body.hpp"

namespace edm::bridge {

class Session;

namespace ops {

/// The body of an operator-function op, or nullopt when `op` is not one of them.
std::optional<Body> dispatch_operator(Session& s, const std::string& op, const Json& msg);

/// cycle.start's own checks and options ({"slot": "main"|"mdi", "dry_run": bool}); an error, or
/// nullopt when the start may be commanded (the options are then set in the job store).
std::optional<Body> prepare_start(Session& s, const Json& msg);

/// program.begin's optional fields: "slot" and "offsets_generation"; an error or nullopt.
std::optional<Body> read_upload_options(const Json& msg, rt::JobSlot& slot,
                                        std::optional<std::uint64_t>& offsets_generation);

/// The "manual" part of machine.info: what this machine's manual motion offers.
Json manual_info_json(const rt::ManualInfo& info);

}  // namespace ops
}  // namespace edm::bridge
