#pragma once
// Fills a block's parameters from the config's `params:` settings (private to the runtime).
// Non-RT.

#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/diagnostics.hpp"

namespace edm::rt {

/// "a, b, c" ("none" for an empty list), for messages that list what would have been valid.
std::string join_names(const std::vector<std::string>& names);

/// Sets every field named in `settings`, converting text to the field's type; reports bad
/// values at the value and unknown keys at the key. `what` names the owner in messages
/// (e.g. "block 'lp' (LowPass)").
void read_params(Block& block, const std::vector<ParamSetting>& settings, std::string_view what,
                 DiagnosticSink& diag);

/// Runs block.validate() and reports each problem at the setting that set the field (or at
/// `fallback` for fields left at their defaults).
void report_validation(const Block& block, const std::vector<ParamSetting>& settings,
                       std::string_view what, const SourceLoc& fallback, DiagnosticSink& diag);

/// Reports problems returned by configure() or validate() the same way.
void report_param_errors(const std::vector<ParamError>& errs,
                         const std::vector<ParamSetting>& settings, std::string_view what,
                         const SourceLoc& fallback, DiagnosticSink& diag);

}  // namespace edm::rt
