// edmhmi mdi "G-code line" — one line interpreted like a program, from where the electrode is,
// run in the runtime's MDI slot; the loaded program is untouched (docs/hmi.md).
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/job_report.hpp"
#include "edm/hmi/job_runner.hpp"
#include "edm/hmi/mdi.hpp"

namespace edmhmi {

int cmd_mdi(const std::string& line, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  const std::optional<edm::hmi::MachineView> fetched = connect_and_fetch_machine(client, settings);
  if (!fetched) return kExitFailure;
  const edm::hmi::MachineView& machine = *fetched;
  const edm::hmi::GcodeResult g =
      edm::hmi::interpret_mdi(line, machine.tables, machine.offsets, machine.position);
  if (!g.ok()) {
    for (const std::string& m : g.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  edm::hmi::RunRequest req;
  req.part = std::string(edm::hmi::kMdiName);
  req.machine = machine.name;
  req.blocks = g.blocks;
  req.frames = g.frames;
  req.slot = "mdi";
  req.offsets_generation = machine.offsets_generation;
  edm::hmi::RunCallbacks cb;
  cb.alarm = [](const std::string& a) { std::fprintf(stderr, "ALARM %s\n", a.c_str()); };
  cb.note = [](const std::string& n) { std::fprintf(stderr, "edmhmi: %s\n", n.c_str()); };
  const edm::hmi::RunResult r = edm::hmi::run_job(client, req, cb, interrupted());
  using edm::hmi::RunOutcome;
  if (r.outcome == RunOutcome::kRefused || r.outcome == RunOutcome::kLost ||
      (r.outcome == RunOutcome::kInterrupted && !r.message.empty())) {
    for (const std::string& m : r.locations) std::fprintf(stderr, "%s\n", m.c_str());
    std::fprintf(stderr, "edmhmi: mdi: %s\n", r.message.c_str());
    if (r.outcome == RunOutcome::kInterrupted) return kExitInterrupted;
    return r.bad_program ? kExitBadInput : kExitFailure;
  }
  std::string where;
  const edm::hmi::JobFigures& f = r.report.end;
  if (f.x_mm && f.y_mm && f.z_mm && !g.frames.empty()) {
    const edm::machining::Vec3 m{*f.x_mm, *f.y_mm, *f.z_mm};
    const edm::hmi::BlockFrame& fr = g.frames.back();
    const edm::machining::Vec3 w = edm::hmi::to_work(m, fr.offset_mm);
    where = "; at " + edm::hmi::format_xyz(w) + " " + edm::hmi::frame_name(fr.frame) + " = " +
            edm::hmi::format_xyz(m) + " machine";
  }
  std::printf("mdi: %s (%zu blocks)%s\n", r.report.outcome.c_str(), g.blocks.size(), where.c_str());
  if (r.outcome == RunOutcome::kInterrupted) return kExitInterrupted;
  return r.outcome == RunOutcome::kFinished && r.report.fault_alarms == 0 ? kExitOk : kExitFailure;
}

}  // namespace edmhmi
