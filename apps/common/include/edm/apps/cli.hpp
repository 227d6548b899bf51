#pragma once
// The command-line conventions of every main() on CLI11 (DESIGN §4): --help prints the help and
// exits 0; a bad argument prints "tool: message" and the usage line on stderr and exits 2.
// Non-RT, main thread only.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

namespace edm::apps {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

/// Fails the parse with `message` as written (a CLI11 validator's text gets the option's name in
/// front; a callback that calls this keeps the tool's own wording).
[[noreturn]] inline void reject(std::string message) {
  throw CLI::ValidationError(std::move(message));
}

/// The whole text as a finite number (CLI11 alone takes "inf" and "nan" as doubles).
inline std::optional<double> finite_number(const std::string& s) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

/// Validators: a finite number; a finite number > 0.
inline const CLI::Validator kFinite(
    [](const std::string& s) {
      return finite_number(s) ? std::string() : "'" + s + "' is not a finite number";
    },
    "NUMBER");
inline const CLI::Validator kPositive(
    [](const std::string& s) {
      const auto v = finite_number(s);
      return v && *v > 0.0 ? std::string() : "'" + s + "' is not a positive number";
    },
    "NUMBER > 0");

/// Parses argv into `app`. Returns an exit code when the program must end here (after --help,
/// 0; after a bad argument, 2, the message and `usage` printed), nullopt to go on.
inline std::optional<int> parse(CLI::App& app, int argc, const char* const* argv,
                                const std::string& usage) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::string message = e.what();
    const bool has_commands = !app.get_subcommands([](const CLI::App*) { return true; }).empty();
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && has_commands &&
        app.get_subcommands().empty()) {
      const auto rest = app.remaining();
      message = rest.empty() ? "missing command" : "unknown command '" + rest.front() + "'";
    } else if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
      const auto extras = app.remaining(true);
      if (!extras.empty()) message = "unknown argument '" + extras.front() + "'";
    }
    std::fprintf(stderr, "%s: %s\nusage: %s\n", app.get_name().c_str(), message.c_str(),
                 usage.c_str());
    return kExitBadInput;
  }
}

}  // namespace edm::apps
