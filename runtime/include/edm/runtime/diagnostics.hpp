#pragma once
// Located error messages for configuration files: "file:line:col: message". The location and
// message types are machining's (edm/machining/diagnostics.hpp), shared with the HMI's reader of
// machine configs; this header adds the runtime's exception and a sink that throws it.
// Non-RT; thread-compatible.

#include <stdexcept>
#include <string>
#include <vector>

#include "edm/machining/diagnostics.hpp"

namespace edm::rt {

using machining::Diagnostic;
using machining::SourceLoc;

/// Thrown by the config parser and the runtime builder (never on an RT path). Holds every
/// problem found, in file order where possible; what() is the first one.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Diagnostic> diags);
  [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const noexcept { return diags_; }

 private:
  std::vector<Diagnostic> diags_;
};

/// Collects diagnostics; throw_if_any() throws a ConfigError with all of them.
class DiagnosticSink : public machining::DiagnosticSink {
 public:
  /// Throws every diagnostic, in file order (line, then column; stable for equal places).
  void throw_if_any() const {
    if (!empty()) {
      throw ConfigError(sorted());
    }
  }
};

}  // namespace edm::rt
