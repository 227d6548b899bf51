// edmhmi hold | resume | stop | estop | reset — the machine commands (docs/runtime.md has the
// state machine; a command in the wrong state is refused with invalid_state, exit 1) — and
// edmhmi override PERCENT, the feed override (any state).
#include <cstdio>

#include "cli.hpp"

namespace edmhmi {

int cmd_machine(std::string_view command, const edm::hmi::ConnectionSettings& settings) {
  const std::string op = command == "hold"     ? "cycle.hold"
                         : command == "resume" ? "cycle.resume"
                         : command == "stop"   ? "cycle.stop"
                                               : std::string(command);  // estop, reset
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const edm::bridge::Reply r = client.request(op);
  if (!r) return report_error(op, r);
  std::printf("%s: machine %s\n", op.c_str(), r.body.value("state", std::string("?")).c_str());
  return kExitOk;
}

int cmd_override(double percent, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const edm::bridge::Reply r = client.request("feed.override", {{"percent", percent}});
  if (!r) return report_error("feed.override", r);
  std::printf("feed.override: %g %%\n", r.body.value("percent", percent));
  return kExitOk;
}

}  // namespace edmhmi
