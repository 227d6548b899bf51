#pragma once
// Which operator functions (DESIGN §12, issue 21: reference, jog, touch-off, work offsets, MDI,
// run from a block, dry run, feed override) the connected edmplc offers, so the page shows a
// control only when it works and says why not otherwise (docs/web.md "Operator functions").
//
// Two sources, in order:
//  1. machine.info's `"ops": [...]` (every op the runtime has; always sent since issue 21) and
//     `"manual": {"available", "home", "touch", …}` (what this machine has wired);
//  2. for an older edmplc without the list, a probe that cannot act: each op name is sent on a
//     fresh TCP connection *before* any hello. edmplc answers `unknown_op` for an op it does not
//     have and `unauthorized` ("hello first") for one it has — an unauthenticated session can run
//     nothing.
// A function is offered when its op is present and, where it names one, the machine's "manual"
// flag is true (the op exists in every runtime; a machine without reference switches cannot home).
//
// Non-RT. probe_ops() blocks up to `timeout` (its own io_context): call it off the I/O thread.
// Pure otherwise (thread-safe).

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "edm/bridge/codec.hpp"

namespace edm::hmi {

struct OperatorFunction {
  std::string_view key;     // the page's control
  std::string_view op;      // the bridge op whose presence says the runtime has the function
  std::string_view manual;  // machine.info "manual" flag that must be true too ("" none)
  std::string_view why;     // the page's note when the flag is false
};
/// MDI, run from a block and dry run are the HMI's own functions (the interpreter, mdi.hpp,
/// resume.hpp): what they need from the runtime — program.begin's "slot": "mdi", drilling blocks
/// with depth_done_mm, cycle.start's "dry_run", offsets_generation — came in one release with
/// offset.get, whose presence is therefore their signal. They also need the job sequencer
/// (EdmJob), which is what manual.available reports.
inline constexpr std::array<OperatorFunction, 8> kOperatorFunctions{{
    {"reference", "home", "home", "this machine has no reference switches wired"},
    {"jog", "jog", "available", "this machine has no manual motion (no EdmJob)"},
    {"touch", "touch", "touch", "this machine has no contact sensing wired"},
    {"offsets", "offset.set", "", ""},
    {"mdi", "offset.get", "available", "this machine has no job sequencer (EdmJob)"},
    {"run_from", "offset.get", "available", "this machine has no job sequencer (EdmJob)"},
    {"dry_run", "offset.get", "available", "this machine has no job sequencer (EdmJob)"},
    {"override", "feed.override", "", ""},
}};

/// The ops the probe asks about: every distinct op of kOperatorFunctions.
std::vector<std::string> operator_function_ops();

/// The ops of `ops` that the bridge at host:port knows (probe 2 above). Throws std::runtime_error
/// when it cannot connect or a reply does not come within `timeout`.
std::vector<std::string> probe_ops(const std::string& host, std::uint16_t port,
                                   const std::vector<std::string>& ops,
                                   std::chrono::milliseconds timeout);

/// {"source": "machine.info" | "probe" | "none", "reference": bool, "jog": bool, …,
///  "work_coordinates": bool (offset.get present), "manual_status": bool, "manual": {…} (as
///  machine.info gave it, or null), "why": {key: "not supported by this edmplc" | the machine's
///  reason}} from machine.info's "ops" when present, else from `probed` (the ops probe_ops()
///  found). `machine_info` is the raw machine.info reply.
bridge::Json capabilities_json(const bridge::Json& machine_info,
                               const std::vector<std::string>* probed);

}  // namespace edm::hmi
