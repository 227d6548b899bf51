// edmhmi electrode — the electrode in the spindle and the electrode table (docs/hmi.md
// "Electrodes"):
//   electrode                          the length compensated with, the table, the tool setter
//   electrode set MM                   a length measured off the machine
//   electrode change ID [--kind K --size MM --material M --new-length MM]
//   electrode measure setter|work [--frame G54]
// `measure setter` first moves there (up to the approach height, then across, as an MDI
// program in machine coordinates), then touches down and waits for the length.
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/electrode_measure.hpp"

namespace edmhmi {
namespace {

using edm::bridge::Json;

void print_table(const Json& b) {
  if (!b.value("known", false)) {
    std::printf("electrode length unknown: no length compensation (edmhmi electrode set <mm>)\n");
  } else {
    std::printf("electrode %s %.4f mm, %.4f mm usable above the %.3f mm margin%s\n",
                b["current"].is_string() ? b["current"].get<std::string>().c_str() : "(unnamed)",
                b.value("length_mm", 0.0), b.value("usable_mm", 0.0), b.value("margin_mm", 0.0),
                b.value("retained", false) ? "" : " (not retained: this run has no retain file)");
  }
  if (b["tool_setter"].is_object()) {
    std::printf("tool setter at X%.3f Y%.3f (Z of a zero length %.3f)\n",
                b["tool_setter"].value("x_mm", 0.0), b["tool_setter"].value("y_mm", 0.0),
                b["tool_setter"].value("z_mm", 0.0));
  }
  if (!b["table"].is_array() || b["table"].empty()) return;
  std::printf("%-2s%-12s %-5s %7s %-10s %9s %9s %6s %9s %8s %s\n", "", "id", "kind", "size",
              "material", "new mm", "now mm", "holes", "drilled", "wear", "measured");
  for (const Json& e : b["table"]) {
    const Json& r = e["wear_ratio"].is_number() ? e["wear_ratio"] : e["wear_ratio_estimated"];
    const std::string ratio =
        r.is_number() ? std::to_string(r.get<double>()).substr(0, 6) : std::string("-");
    std::printf("%-2s%-12s %-5s %7.3f %-10s %9.3f %9.3f %6lld %9.3f %8s %s\n",
                e.value("id", "") == b.value("current", Json("")).get<std::string>() ? "*" : "",
                e.value("id", "").c_str(), e.value("kind", "").c_str(), e.value("size_mm", 0.0),
                e.value("material", "").c_str(), e.value("new_length_mm", 0.0),
                e.value("length_mm", 0.0), static_cast<long long>(e.value("holes", 0)),
                e.value("drilled_mm", 0.0),
                (ratio + (r.is_number() && !e["wear_ratio"].is_number() ? "~" : "")).c_str(),
                e.value("measured", false) ? "yes" : "NO");
  }
}

int measure(edm::bridge::Client& client, const ElectrodeArgs& a) {
  edm::hmi::MeasureRequest req;
  req.reference = a.reference;
  req.frame = a.frame;
  const edm::hmi::MeasureOutcome o = edm::hmi::measure_electrode(
      client, req, interrupted(),
      [](const std::string& n) { std::fprintf(stderr, "edmhmi: %s\n", n.c_str()); });
  if (o.kind == edm::hmi::MeasureOutcome::Kind::kInterrupted) return kExitInterrupted;
  if (!o.ok()) {
    std::fprintf(stderr, "edmhmi: electrode measure: %s\n", o.error.c_str());
    return kExitFailure;
  }
  std::printf("measured %.4f mm (the estimate was %.4f mm)\n", o.length_mm, o.was_mm);
  print_table(o.electrode);
  return kExitOk;
}

}  // namespace

int cmd_electrode(const ElectrodeArgs& a, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  if (a.action == "measure") return measure(client, a);
  edm::bridge::Reply r;
  const char* op = "electrode.get";
  if (a.action == "set") {
    op = "electrode.set";
    r = client.request(op, {{"length_mm", a.length_mm}});
  } else if (a.action == "change") {
    op = "electrode.change";
    Json p{{"electrode", a.id}};
    if (!a.kind.empty()) p["kind"] = a.kind;
    if (!a.material.empty()) p["material"] = a.material;
    if (a.size_mm > 0.0) p["size_mm"] = a.size_mm;
    if (a.new_length_mm > 0.0) p["new_length_mm"] = a.new_length_mm;
    r = client.request(op, p);
  } else {
    r = client.request(op);
  }
  if (!r) return report_error(op, r);
  print_table(r.body);
  if (a.action == "change") {
    std::printf("now measure it: edmhmi electrode measure setter (or work)\n");
  }
  return kExitOk;
}

}  // namespace edmhmi
