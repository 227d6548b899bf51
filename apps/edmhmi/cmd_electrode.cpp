// edmhmi electrode — the electrode in the spindle and the electrode table (docs/hmi.md
// "Electrodes"):
//   electrode                          the length compensated with, the table, the tool setter
//   electrode set MM                   a length measured off the machine
//   electrode change ID [--kind K --size MM --material M --new-length MM]
//   electrode measure setter|work [--frame G54]
// `measure setter` first moves there (up to the approach height, then across, as an MDI
// program in machine coordinates), then touches down and waits for the length.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "cli.hpp"
#include "edm/hmi/job_runner.hpp"

namespace edmhmi {
namespace {

using edm::bridge::Json;
using namespace std::chrono_literals;

/// How high above the tool setter the tip approaches it, if its length is as the table says:
/// the touch searches 20 mm, so a length wrong by up to ±10 mm is still found.
constexpr double kApproachMm = 10.0;

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

/// Moves the electrode over the tool setter: up to its approach height (never down), across.
int move_to_setter(edm::bridge::Client& client, const edm::hmi::ConnectionSettings& settings,
                   const Json& info) {
  const std::optional<edm::hmi::MachineView> m = connect_and_fetch_machine(client, settings);
  if (!m) return kExitFailure;
  const Json& ts = info["tool_setter"];
  const double approach = ts.value("z_mm", 0.0) + info.value("length_mm", 0.0) + kApproachMm;
  const double z = std::max(m->position.z, approach);
  edm::machining::MotionBlock up;
  up.kind = edm::machining::MotionKind::kRapid;
  up.line = 1;
  up.target = {m->position.x, m->position.y, z};
  edm::machining::MotionBlock across = up;
  across.line = 2;
  across.target = {ts.value("x_mm", 0.0), ts.value("y_mm", 0.0), z};
  edm::machining::MotionBlock end;
  end.kind = edm::machining::MotionKind::kEnd;
  end.line = 3;
  edm::hmi::RunRequest req;
  req.part = "tool setter";
  req.machine = m->name;
  req.blocks = {up, across, end};
  req.slot = "mdi";
  req.offsets_generation = m->offsets_generation;
  std::fprintf(stderr, "edmhmi: to the tool setter X%.3f Y%.3f at Z%.3f\n", across.target.x,
               across.target.y, z);
  const edm::hmi::RunResult r = edm::hmi::run_job(client, req, {}, interrupted());
  if (r.outcome != edm::hmi::RunOutcome::kFinished) {
    std::fprintf(stderr, "edmhmi: electrode measure: the move to the tool setter did not end: %s\n",
                 r.message.c_str());
    return r.outcome == edm::hmi::RunOutcome::kInterrupted ? kExitInterrupted : kExitFailure;
  }
  return kExitOk;
}

int measure(edm::bridge::Client& client, const ElectrodeArgs& a,
            const edm::hmi::ConnectionSettings& settings) {
  const edm::bridge::Reply info = client.request("electrode.get");
  if (!info) return report_error("electrode.get", info);
  if (a.reference == "setter") {
    if (!info.body["tool_setter"].is_object()) {
      std::fprintf(stderr,
                   "edmhmi: electrode measure: this machine has no tool setter "
                   "(machine.electrode.tool_setter); measure on the work instead\n");
      return kExitFailure;
    }
    if (const int rc = move_to_setter(client, settings, info.body); rc != kExitOk) return rc;
  }
  Json params{{"reference", a.reference}};
  if (!a.frame.empty()) params["frame"] = a.frame;
  const edm::bridge::Reply m = client.request("electrode.measure", params);
  if (!m) return report_error("electrode.measure", m);
  const auto seq = m.body.value("seq", std::uint64_t{0});
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (std::chrono::steady_clock::now() < deadline && !interrupted().load()) {
    const edm::bridge::Reply g = client.request("electrode.get");
    if (!g) return report_error("electrode.get", g);
    const Json& last = g.body["last_measure"];
    if (last.is_object() && last.value("seq", std::uint64_t{0}) == seq) {
      if (!last.value("ok", false)) {
        std::fprintf(stderr, "edmhmi: electrode measure: %s\n",
                     last.value("error", std::string("failed")).c_str());
        return kExitFailure;
      }
      std::printf("measured %.4f mm (the estimate was %.4f mm)\n", last.value("length_mm", 0.0),
                  last.value("was_mm", 0.0));
      print_table(g.body);
      return kExitOk;
    }
    std::this_thread::sleep_for(50ms);  // polling the machine's state, as every wait here
  }
  std::fprintf(stderr, "edmhmi: electrode measure: no result within 120 s\n");
  return kExitFailure;
}

}  // namespace

int cmd_electrode(const ElectrodeArgs& a, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  if (a.action == "measure") return measure(client, a, settings);
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
