#pragma once
// Located error messages for configuration files: "file:line:col: message".
// Non-RT; thread-compatible.

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace edm::rt {

/// A position in a source file; line and col are 1-based (0 = unknown).
struct SourceLoc {
  std::string file;
  int line{0};
  int col{0};
};

struct Diagnostic {
  SourceLoc loc;
  std::string message;
  /// "file:line:col: message" (the parts that are known).
  [[nodiscard]] std::string str() const;
};

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
class DiagnosticSink {
 public:
  void error(const SourceLoc& loc, std::string message) {
    diags_.push_back({loc, std::move(message)});
  }
  [[nodiscard]] bool empty() const noexcept { return diags_.empty(); }
  [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const noexcept { return diags_; }
  /// Throws every diagnostic, in file order (line, then column; stable for equal places).
  void throw_if_any() const {
    if (!diags_.empty()) {
      std::vector<Diagnostic> sorted = diags_;
      std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic& a, const Diagnostic& b) {
        return a.loc.line != b.loc.line ? a.loc.line < b.loc.line : a.loc.col < b.loc.col;
      });
      throw ConfigError(std::move(sorted));
    }
  }

 private:
  std::vector<Diagnostic> diags_;
};

}  // namespace edm::rt
