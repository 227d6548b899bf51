// The job queue (job_queue.hpp, docs/hmi.md "A job queue").
#include "edm/hmi/job_queue.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <thread>

#include "edm/hmi/gcode.hpp"
#include "edm/hmi/resume.hpp"
#include "edm/machining/wear_precomp.hpp"

namespace edm::hmi {
namespace {

using bridge::Json;
using machining::HoleWear;
using machining::MotionBlock;

/// How far below its soft limit the queue parks Z for a change (a rapid that ends on the limit
/// would trip it in its settling).
constexpr double kBelowTopMm = 1.0;

/// What identifies the electrode in the spindle: a change, or a new measurement, alters it.
struct ElectrodeState {
  std::string id;
  double length_mm{0.0};
  double usable_mm{0.0};
  bool measured{true};
  std::uint64_t measure_seq{0};
};

std::optional<ElectrodeState> electrode_state(bridge::Client& client) {
  const bridge::Reply r = client.request("electrode.get");
  if (!r || !r.body.is_object()) return std::nullopt;
  ElectrodeState s;
  s.length_mm = r.body.value("length_mm", 0.0);
  s.usable_mm = r.body.value("usable_mm", s.length_mm);
  if (r.body.value("current", Json()).is_string()) {
    s.id = r.body["current"].get<std::string>();
    for (const Json& e : r.body.value("table", Json::array())) {
      if (e.value("id", "") == s.id) s.measured = e.value("measured", true);
    }
  }
  if (const Json& m = r.body.value("last_measure", Json()); m.is_object()) {
    s.measure_seq = m.value("seq", std::uint64_t{0});
  }
  return s;
}

/// The first hole of `blocks` the electrode left would not finish, and whether it is the
/// program's first; nullopt when every hole is covered (a machine whose electrode length is
/// unknown checks nothing: 0).
struct ShortHole {
  HoleWear hole;
  bool first{false};
};
std::optional<ShortHole> first_short_hole(const std::vector<MotionBlock>& blocks,
                                          const machining::MachineTables& tables,
                                          const ElectrodeState& e) {
  if (!(e.length_mm > 0.0)) return std::nullopt;
  const std::vector<HoleWear> plan = machining::planned_wear(blocks, tables);
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (plan[i].cumulative_mm > e.usable_mm) return ShortHole{plan[i], i == 0};
  }
  return std::nullopt;
}

/// Waits until the electrode in the spindle is another one or another length, and measured.
/// False on the interrupt.
bool wait_for_change(bridge::Client& client, const ElectrodeState& before, const QueueCallbacks& cb,
                     const std::atomic<bool>& interrupt) {
  if (cb.waiting) cb.waiting(true);
  struct Done {
    const QueueCallbacks& cb;
    ~Done() {
      if (cb.waiting) cb.waiting(false);
    }
  } done{cb};
  while (!interrupt.load()) {
    std::this_thread::sleep_for(cb.electrode_poll);  // polling the machine, as edmhmi does
    const std::optional<ElectrodeState> now = electrode_state(client);
    if (!now || !now->measured) continue;
    if (now->id != before.id || now->measure_seq != before.measure_seq ||
        now->length_mm != before.length_mm) {
      return true;
    }
  }
  return false;
}

std::string mm(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

}  // namespace

QueueResult run_queue(bridge::Client& client, const std::vector<QueueItem>& items,
                      const QueueCallbacks& cb, const std::atomic<bool>& interrupt) {
  QueueResult out;
  const auto note = [&cb](const std::string& n) {
    if (cb.note) cb.note(n);
  };
  for (const QueueItem& item : items) {
    for (int run = 1; run <= item.repeat; ++run) {
      int from_line = 0;  // > 0: go on from this line's hole (after an electrode change)
      for (;;) {
        if (interrupt.load()) {
          out.message = "interrupted";
          return out;
        }
        const MachineView machine = fetch_machine(client);
        GcodeOptions options;
        options.start_mm = machine.position;
        options.offsets = machine.offsets;
        for (machining::Vec3& origin : options.offsets.frame) {  // the run's place in the row
          origin.x += (run - 1) * item.step_x_mm;
          origin.y += (run - 1) * item.step_y_mm;
        }
        const GcodeResult g = interpret_gcode(item.text, item.part, machine.tables, options);
        if (!g.ok()) {
          out.message = item.part + ": " + (g.messages().empty() ? "" : g.messages().front());
          return out;
        }
        RunRequest req;
        req.part = item.part;
        req.machine = machine.name;
        req.blocks = g.blocks;
        req.frames = g.frames;
        req.offsets_generation = machine.offsets_generation;
        if (from_line > 0) {
          ResumePlan plan = plan_resume(g, machine.tables, from_line);
          if (!plan.ok()) {
            out.message =
                item.part + ": from line " + std::to_string(from_line) + ": " + plan.error;
            return out;
          }
          req.blocks = std::move(plan.blocks);
          req.frames = std::move(plan.frames);
        }
        const std::optional<ElectrodeState> electrode = electrode_state(client);
        if (!electrode) {
          out.message = "electrode.get failed: the electrode left is not known";
          return out;
        }
        const std::optional<ShortHole> shortage =
            first_short_hole(req.blocks, machine.tables, *electrode);
        const HoleWear* short_hole = shortage ? &shortage->hole : nullptr;
        QueueJob job;
        job.part = item.part;
        job.run = run;
        job.from_line = from_line;
        bool change_after = false;
        if (short_hole) {
          const std::string why = item.part + " (run " + std::to_string(run) + "): the electrode " +
                                  (electrode->id.empty() ? std::string() : electrode->id + " ") +
                                  "would run out in " + "the hole of line " +
                                  std::to_string(short_hole->line) + " (" +
                                  mm(short_hole->cumulative_mm) + " mm planned, " +
                                  mm(electrode->usable_mm) + " mm usable)";
          if (shortage->first) {
            note(why +
                 ": change the electrode and measure it (edmhmi electrode change …, "
                 "edmhmi electrode measure setter); the queue goes on then");
            if (!wait_for_change(client, *electrode, cb, interrupt)) {
              out.message = "interrupted while waiting for an electrode change";
              return out;
            }
            continue;  // interpreted again, with the new electrode
          }
          // The holes before it run now; the machine stops before it.
          note(why + ": the holes before it run, then the machine stops for a change");
          // ... and ends with the electrode raised to the top of Z (machine coordinates, no
          // length compensation): a new electrode, longer than the worn one, must fit in.
          req.blocks.resize(short_hole->block);
          MotionBlock up = req.blocks.back();
          up.kind = machining::MotionKind::kRapid;
          up.line = short_hole->line;
          up.electrode_ref_mm = 0.0;
          for (const MotionBlock& b : req.blocks) up.target.z = std::max(up.target.z, b.target.z);
          up.target.z = std::max(up.target.z, machine.position.z);
          if (const machining::AxisLimits* z = machine.tables.axis('Z')) {
            up.target.z = std::max(up.target.z, z->max_mm - kBelowTopMm);
          }
          MotionBlock end;
          end.kind = machining::MotionKind::kEnd;
          end.line = short_hole->line;
          end.target = up.target;
          req.blocks.push_back(up);
          req.blocks.push_back(end);
          if (!req.frames.empty()) req.frames.resize(req.blocks.size(), req.frames.back());
          job.before_line = short_hole->line;
          change_after = true;
        }
        if (cb.job_start) cb.job_start(job);
        job.result = run_job(client, req, cb.run, interrupt);
        out.jobs.push_back(job);
        if (cb.job_done) cb.job_done(out.jobs.back());
        if (job.result.outcome != RunOutcome::kFinished) {
          out.message =
              item.part + " (run " + std::to_string(run) + ") did not finish: " +
              (job.result.message.empty() ? job.result.report.outcome : job.result.message);
          return out;
        }
        if (!change_after) break;
        // What is in the spindle now, before the operator is asked to change it.
        const std::optional<ElectrodeState> before = electrode_state(client);
        note(item.part + ": stopped before the hole of line " + std::to_string(job.before_line) +
             ": change the electrode and measure it; the queue goes on from that line then");
        if (!before || !wait_for_change(client, *before, cb, interrupt)) {
          out.message = "interrupted while waiting for an electrode change";
          return out;
        }
        from_line = job.before_line;
      }
    }
  }
  out.ok = true;
  return out;
}

}  // namespace edm::hmi
