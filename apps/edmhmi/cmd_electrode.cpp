// edmhmi electrode [set MM] — the electrode length the job compensates with (electrode.get /
// electrode.set, docs/hmi.md "Electrode length").
#include <cstdio>

#include "cli.hpp"

namespace edmhmi {

int cmd_electrode(double length_mm, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const bool set = length_mm > 0.0;
  const edm::bridge::Reply r = set ? client.request("electrode.set", {{"length_mm", length_mm}})
                                   : client.request("electrode.get");
  if (!r) return report_error(set ? "electrode.set" : "electrode.get", r);
  if (!r.body.value("known", false)) {
    std::printf("electrode length unknown: no length compensation (edmhmi electrode set <mm>)\n");
    return kExitOk;
  }
  std::printf(
      "electrode %.4f mm%s\n", r.body.value("length_mm", 0.0),
      r.body.value("retained", false) ? "" : " (not retained: this run has no retain file)");
  return kExitOk;
}

}  // namespace edmhmi
