// Measuring the electrode (electrode_measure.hpp).
#include "edm/hmi/electrode_measure.hpp"

#include <algorithm>
#include <cstdio>
#include <thread>

#include "edm/hmi/job_runner.hpp"

namespace edm::hmi {
namespace {

using bridge::Json;

std::string reply_error(std::string_view op, const bridge::Reply& r) {
  return std::string(op) + ": " +
         (r.code ? std::string(bridge::to_string(*r.code)) : std::string("transport")) + ": " +
         r.message;
}

MeasureOutcome failed(std::string why) {
  MeasureOutcome o;
  o.error = std::move(why);
  return o;
}

/// Up to the approach height over the tool setter (never down), then across it.
MeasureOutcome move_to_setter(bridge::Client& client, const Json& electrode,
                              const std::atomic<bool>& interrupt,
                              const std::function<void(const std::string&)>& note) {
  const MachineView m = fetch_machine(client);
  const Json& ts = electrode["tool_setter"];
  const double approach =
      ts.value("z_mm", 0.0) + electrode.value("length_mm", 0.0) + kSetterApproachMm;
  const double z = std::max(m.position.z, approach);
  machining::MotionBlock up;
  up.kind = machining::MotionKind::kRapid;
  up.line = 1;
  up.target = {m.position.x, m.position.y, z};
  machining::MotionBlock across = up;
  across.line = 2;
  across.target = {ts.value("x_mm", 0.0), ts.value("y_mm", 0.0), z};
  machining::MotionBlock end;
  end.kind = machining::MotionKind::kEnd;
  end.line = 3;
  end.target = across.target;
  RunRequest req;
  req.part = "tool setter";
  req.machine = m.name;
  req.blocks = {up, across, end};
  req.slot = "mdi";
  req.offsets_generation = m.offsets_generation;
  if (note) {
    char b[96];
    std::snprintf(b, sizeof b, "to the tool setter X%.3f Y%.3f at Z%.3f", across.target.x,
                  across.target.y, z);
    note(b);
  }
  const RunResult r = run_job(client, req, {}, interrupt);
  MeasureOutcome o;
  if (r.outcome == RunOutcome::kFinished) {
    o.kind = MeasureOutcome::Kind::kMeasured;  // (moved: the caller goes on)
  } else if (r.outcome == RunOutcome::kInterrupted) {
    o.kind = MeasureOutcome::Kind::kInterrupted;
  } else {
    o.error = "the move to the tool setter did not end: " +
              (r.message.empty() ? r.report.outcome : r.message);
  }
  return o;
}

}  // namespace

MeasureOutcome measure_electrode(bridge::Client& client, const MeasureRequest& request,
                                 const std::atomic<bool>& interrupt,
                                 const std::function<void(const std::string&)>& note) {
  if (request.reference != "setter" && request.reference != "work") {
    return failed("the reference is 'setter' or 'work', not '" + request.reference + "'");
  }
  const bridge::Reply info = client.request("electrode.get");
  if (!info) return failed(reply_error("electrode.get", info));
  if (request.reference == "setter") {
    if (!info.body["tool_setter"].is_object()) {
      return failed(
          "this machine has no tool setter (machine.electrode.tool_setter); measure on the work "
          "instead");
    }
    try {
      MeasureOutcome moved = move_to_setter(client, info.body, interrupt, note);
      if (!moved.ok()) return moved;
    } catch (const bridge::ClientError& e) {
      return failed(std::string("to the tool setter: ") + e.what());
    }
  }
  Json params{{"reference", request.reference}};
  if (!request.frame.empty()) params["frame"] = request.frame;
  const bridge::Reply m = client.request("electrode.measure", params);
  if (!m) return failed(reply_error("electrode.measure", m));
  if (note) note("touching down on the " + request.reference);
  const auto seq = m.body.value("seq", std::uint64_t{0});
  const auto deadline = std::chrono::steady_clock::now() + request.limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (interrupt.load()) {
      client.request("jog.stop");  // the touch is a manual motion: jog.stop ends it
      MeasureOutcome o;
      o.kind = MeasureOutcome::Kind::kInterrupted;
      return o;
    }
    const bridge::Reply g = client.request("electrode.get");
    if (!g) return failed(reply_error("electrode.get", g));
    const Json& last = g.body["last_measure"];
    if (last.is_object() && last.value("seq", std::uint64_t{0}) == seq) {
      if (!last.value("ok", false)) return failed(last.value("error", std::string("failed")));
      MeasureOutcome o;
      o.kind = MeasureOutcome::Kind::kMeasured;
      o.length_mm = last.value("length_mm", 0.0);
      o.was_mm = last.value("was_mm", 0.0);
      o.electrode = g.body;
      return o;
    }
    std::this_thread::sleep_for(request.poll);  // polling the machine's state, as edmhmi does
  }
  return failed("no result within " + std::to_string(request.limit.count()) + " s");
}

}  // namespace edm::hmi
