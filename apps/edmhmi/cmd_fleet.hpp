#pragma once
// `edmhmi fleet --broker HOST:PORT`: every machine heard on an MQTT broker (Sparkplug B, as
// edmplc's `mqtt:` publishes it), with its state, job progress and alarms; once (after --wait
// seconds) or, with --watch, refreshed until Ctrl-C. docs/mqtt.md. Needs no edmplc bridge.

#include <string>

#include "edm/apps/cli.hpp"

namespace edmhmi {

struct FleetArgs {
  std::string broker;  // HOST:PORT
  std::string group;   // "" = every group
  bool watch{false};
  bool json{false};
  double wait_s{3.0};     // one-shot: listen this long before printing
  double refresh_s{1.0};  // --watch: reprint period
  std::string username;
  std::string password_file;
  std::string tls_ca;
  bool no_rebirth{false};
};

/// Adds the `fleet` subcommand and its options to app.
void add_fleet_command(CLI::App& app, FleetArgs& args);
int cmd_fleet(const FleetArgs& args);

}  // namespace edmhmi
