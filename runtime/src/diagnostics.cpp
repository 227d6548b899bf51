#include "edm/runtime/diagnostics.hpp"

#include <utility>

namespace edm::rt {

namespace {

// runtime_error needs its message before diags_ exists, so build it from the argument.
std::string first_message(const std::vector<Diagnostic>& diags) {
  return diags.empty() ? std::string("invalid configuration") : diags.front().str();
}

}  // namespace

ConfigError::ConfigError(std::vector<Diagnostic> diags)
    : std::runtime_error(first_message(diags)), diags_(std::move(diags)) {}

}  // namespace edm::rt
