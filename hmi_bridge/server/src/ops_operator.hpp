#pragma once
// What the operator functions' ops share with the other ops (DESIGN §12, issue 21;
// docs/protocol.md "Operator functions"; the handlers are in ops_handlers.hpp):
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
