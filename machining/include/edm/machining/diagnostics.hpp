#pragma once
// Located error messages for configuration files: "file:line:col: message". Shared by the
// runtime's config parser and machining's machine-table reader so both word and place a problem
// the same way. Non-RT; thread-compatible.

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace edm::machining {

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

/// Collects diagnostics in the order they were found.
class DiagnosticSink {
 public:
  void error(const SourceLoc& loc, std::string message) {
    diags_.push_back({loc, std::move(message)});
  }
  [[nodiscard]] bool empty() const noexcept { return diags_.empty(); }
  [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const noexcept { return diags_; }
  /// Every diagnostic in file order (line, then column; stable for equal places).
  [[nodiscard]] std::vector<Diagnostic> sorted() const {
    std::vector<Diagnostic> out = diags_;
    std::stable_sort(out.begin(), out.end(), [](const Diagnostic& a, const Diagnostic& b) {
      return a.loc.line != b.loc.line ? a.loc.line < b.loc.line : a.loc.col < b.loc.col;
    });
    return out;
  }

 private:
  std::vector<Diagnostic> diags_;
};

}  // namespace edm::machining
