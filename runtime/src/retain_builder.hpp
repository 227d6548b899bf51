#pragma once
// Private to the runtime builder: the retain store of a config's `retain:` section — the retained
// variables checked (file:line:col), the file found through the state directory, loaded and
// restored (a corrupt file set aside with alarm 180), and the interrupted job's record (alarm 182).
// Non-RT; thread-compatible.

#include "edm/runtime/config.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::rt {

/// Gives `rt` its retain store (none without `retain.file`, or with options.load_retain false:
/// --check and --list-vars construct none). Problems go to `diag`.
void build_retain(const Config& cfg, const BuildOptions& options, Runtime& rt,
                  DiagnosticSink& diag);

}  // namespace edm::rt
