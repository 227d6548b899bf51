#pragma once
// Located error messages for configuration files: "file:line:col: message".
// Non-RT; thread-compatible.

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
  void throw_if_any() const {
    if (!diags_.empty()) {
      throw ConfigError(diags_);
    }
  }

 private:
  std::vector<Diagnostic> diags_;
};

}  // namespace edm::rt
