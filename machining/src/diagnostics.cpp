#include "edm/machining/diagnostics.hpp"

namespace edm::machining {

std::string Diagnostic::str() const {
  std::string out = loc.file;
  if (loc.line > 0) {
    if (!out.empty()) {
      out += ':';
    }
    out += std::to_string(loc.line);
    if (loc.col > 0) {
      out += ':' + std::to_string(loc.col);
    }
  }
  if (out.empty()) {
    return message;
  }
  return out + ": " + message;
}

}  // namespace edm::machining
