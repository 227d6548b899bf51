// edmhmi run [--detach] [--quiet] [--dry-run] [--from N [--depth-done MM]] PART.nc — interpret
// against the machine's own tables and work offsets, upload, start, show progress, print the job
// report (docs/hmi.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

#include "cli.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/hmi/job_runner.hpp"
#include "edm/hmi/resume.hpp"

namespace edmhmi {

namespace {

/// Progress on a terminal: one line redrawn in place at most 5 times a second. Elsewhere (a log,
/// a pipe): a plain line every 10 s and whenever the block changes.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet), tty_(isatty(STDERR_FILENO) == 1) {}

  void show(const edm::hmi::ProgressView& v) {
    if (quiet_) return;
    const auto now = std::chrono::steady_clock::now();
    const bool block_changed = v.block != last_block_;
    if (tty_) {
      if (now - last_ < std::chrono::milliseconds(200) && !block_changed) return;
      std::fprintf(stderr, "\r%s\033[K", edm::hmi::format_progress(v).c_str());
      open_line_ = true;
    } else {
      if (now - last_ < std::chrono::seconds(10) && !block_changed) return;
      std::fprintf(stderr, "%s\n", edm::hmi::format_progress(v).c_str());
    }
    std::fflush(stderr);
    last_ = now;
    last_block_ = v.block;
  }
  /// A message on its own line (ends the redrawn line first).
  void message(const std::string& m) {
    end_line();
    std::fprintf(stderr, "%s\n", m.c_str());
  }
  void end_line() {
    if (open_line_) std::fputc('\n', stderr);
    open_line_ = false;
  }

 private:
  bool quiet_;
  bool tty_;
  bool open_line_{false};
  std::chrono::steady_clock::time_point last_{};
  std::uint64_t last_block_{~std::uint64_t{0}};
};

std::string xyz(const edm::machining::Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "X %.3f Y %.3f Z %.3f", v.x, v.y, v.z);
  return buf;
}

/// --from N: the depth the drilling block on that line already has — --depth-done, else the
/// runtime's record of the last job when it ended on that very line, else 0 — said on stderr.
/// Returns the plan, or prints why not and returns nullopt.
std::optional<edm::hmi::ResumePlan> plan_from(const RunArgs& args, const edm::hmi::GcodeResult& g,
                                              const edm::hmi::MachineView& machine) {
  edm::hmi::ResumePlan plan = edm::hmi::plan_resume(g, machine.tables, args.from_line, 0.0);
  if (plan.ok() && plan.drill) {
    double depth = 0.0;
    std::optional<edm::hmi::DrillResume> state;
    std::string why;
    if (args.depth_done) {
      depth = *args.depth_done;
      why = "--depth-done";
    } else if (!machine.last_job) {
      why = "the runtime has no record of a last job";
    } else if (machine.last_job->line != plan.line) {
      why = "the last job (" + machine.last_job->outcome + ") ended on line " +
            std::to_string(machine.last_job->line) + ", not on line " + std::to_string(plan.line);
    } else if (!machine.last_job->depth_mm) {
      why = "the last job's record has no depth";
    } else {
      depth = std::max(0.0, *machine.last_job->depth_mm);
      why = "the runtime's record of the last job (" + machine.last_job->outcome + " on line " +
            std::to_string(plan.line) + ")";
      if (machine.last_job->touch_z_mm && machine.last_job->wear_mm) {
        state = edm::hmi::DrillResume{*machine.last_job->touch_z_mm, *machine.last_job->wear_mm};
        why += ", its touch at Z " + std::to_string(state->touch_z_mm) + " and wear " +
               std::to_string(state->wear_mm) + " mm";
      }
    }
    std::fprintf(stderr, "edmhmi: line %d drills on from %.4f mm deep (%s)\n", plan.line, depth,
                 why.c_str());
    plan = edm::hmi::plan_resume(g, machine.tables, args.from_line, depth, state);
  } else if (plan.ok() && args.depth_done && *args.depth_done > 0.0) {
    plan = edm::hmi::plan_resume(g, machine.tables, args.from_line, *args.depth_done);
  }
  if (!plan.ok()) {
    std::fprintf(stderr, "%s: --from %d: %s\n", args.part.c_str(), args.from_line,
                 plan.error.c_str());
    return std::nullopt;
  }
  const edm::machining::MotionBlock& first = plan.blocks[plan.prologue];
  std::fprintf(stderr,
               "edmhmi: resuming at line %d (block %zu of %zu): rapid up to Z %.3f, over and down "
               "to %s, then rotation %s, flushing %s, E%d\n",
               plan.line, plan.first + 1, g.blocks.size(), plan.clearance_z_mm,
               xyz(plan.blocks[plan.prologue - 4].target).c_str(),
               plan.blocks[plan.prologue - 3].on ? "on" : "off",
               plan.blocks[plan.prologue - 2].on ? "on" : "off",
               plan.blocks[plan.prologue - 1].condition);
  if (plan.drill) {
    std::fprintf(stderr, "edmhmi: line %d: depth done %.4f mm, Z travel %.4f mm\n", first.line,
                 plan.depth_done_mm, plan.blocks[*plan.drill].z_travel_mm);
  }
  return plan;
}

}  // namespace

int cmd_run(const RunArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const bool detach = args.detach, quiet = args.quiet;
  const std::string& part = args.part;
  std::string text;
  if (!read_text_file(part, text)) return kExitBadInput;

  edm::bridge::Client client;
  const std::optional<edm::hmi::MachineView> fetched = connect_and_fetch_machine(client, settings);
  if (!fetched) return kExitFailure;
  const edm::hmi::MachineView& machine = *fetched;
  // The program starts where the electrode is now, against the conditions and limits of the
  // machine it runs on.
  // In work coordinates: the frames are the machine's (offset.get).
  edm::hmi::GcodeOptions options;
  options.start_mm = machine.position;
  options.offsets = machine.offsets;
  const edm::hmi::GcodeResult g = edm::hmi::interpret_gcode(text, part, machine.tables, options);
  if (!g.ok()) {
    for (const std::string& m : g.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  if (!quiet && machine.tables.kind == edm::machining::MachineKind::kWire) {
    std::fprintf(stderr,
                 "edmhmi: %s: %zu blocks (%d cut blocks, %.3f mm of cut path) → %s at %s:%u\n",
                 part.c_str(), g.blocks.size(), g.cut_blocks, g.cut_length_mm, machine.name.c_str(),
                 settings.host.c_str(), unsigned{settings.port});
  } else if (!quiet) {
    std::fprintf(stderr,
                 "edmhmi: %s: %zu blocks (%d drilling, %.3f mm, estimated electrode wear %.3f "
                 "mm) → %s at %s:%u\n",
                 part.c_str(), g.blocks.size(), g.drill_blocks, g.drill_depth_mm,
                 g.electrode_wear_mm, machine.name.c_str(), settings.host.c_str(),
                 unsigned{settings.port});
    if (!machine.offsets_generation) {
      std::fprintf(stderr,
                   "edmhmi: this edmplc has no work offsets (offset.get): G54..G59 are 0\n");
    }
  }

  edm::hmi::RunRequest req;
  req.part = part;
  req.machine = machine.name;
  req.blocks = g.blocks;
  req.frames = g.frames;
  req.offsets_generation = machine.offsets_generation;
  if (args.from_line > 0) {
    std::optional<edm::hmi::ResumePlan> plan = plan_from(args, g, machine);
    if (!plan) return kExitBadInput;
    req.blocks = std::move(plan->blocks);
    req.frames = std::move(plan->frames);
  } else if (args.depth_done) {
    return usage("run: --depth-done goes with --from N");
  }
  req.dry_run = args.dry_run;
  if (args.dry_run && !quiet) {
    std::fprintf(stderr,
                 "edmhmi: dry run: the generator stays off; drilling and orbit blocks are "
                 "skipped\n");
  }
  req.detach = detach;
  ProgressPrinter printer(quiet);
  edm::hmi::RunCallbacks cb;
  cb.progress = [&printer](const edm::hmi::ProgressView& v) { printer.show(v); };
  cb.alarm = [&printer](const std::string& a) { printer.message("ALARM " + a); };
  cb.note = [&printer](const std::string& n) { printer.message("edmhmi: " + n); };
  const edm::hmi::RunResult r = edm::hmi::run_job(client, req, cb, interrupted());
  printer.end_line();

  using edm::hmi::RunOutcome;
  switch (r.outcome) {
    case RunOutcome::kRefused:
      for (const std::string& m : r.locations) std::fprintf(stderr, "%s\n", m.c_str());
      std::fprintf(stderr, "edmhmi: %s\n", r.message.c_str());
      return r.bad_program ? kExitBadInput : kExitFailure;
    case RunOutcome::kDetached:
      std::printf("%s: started on %s; follow it with edmhmi status\n", part.c_str(),
                  machine.name.c_str());
      return kExitOk;
    case RunOutcome::kLost:
      std::fprintf(stderr, "edmhmi: %s\n", r.message.c_str());
      return kExitFailure;
    case RunOutcome::kInterrupted:
      if (!r.message.empty()) {  // no report: the end was not seen
        std::fprintf(stderr, "edmhmi: %s\n", r.message.c_str());
        return kExitInterrupted;
      }
      break;
    case RunOutcome::kFinished:
    case RunOutcome::kAborted: break;
  }
  std::fputs(edm::hmi::format_report(r.report).c_str(), stdout);
  std::fflush(stdout);
  if (r.outcome == RunOutcome::kInterrupted) return kExitInterrupted;
  // Warnings (e.g. a watchdog warning on a loaded PC) are reported; a fault alarm fails the run.
  return r.outcome == RunOutcome::kFinished && r.report.fault_alarms == 0 ? kExitOk : kExitFailure;
}

}  // namespace edmhmi
