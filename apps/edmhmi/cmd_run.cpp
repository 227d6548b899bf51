// edmhmi run [--detach] [--quiet] PART.nc — interpret against the machine's own tables, upload,
// start, show progress, print the job report (docs/hmi.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/gcode.hpp"
#include "edm/hmi/job_runner.hpp"

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

}  // namespace

int cmd_run(const RunArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const bool detach = args.detach, quiet = args.quiet;
  const std::string& part = args.part;
  std::string text;
  if (!read_text_file(part, text)) return kExitBadInput;

  edm::bridge::Client client;
  if (!connect(client, settings, /*auto_reconnect=*/true)) return kExitFailure;
  edm::hmi::MachineView machine;
  try {
    machine = edm::hmi::fetch_machine(client);
  } catch (const edm::bridge::ClientError& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return kExitFailure;
  }
  // The program starts where the electrode is now, against the conditions and limits of the
  // machine it runs on.
  edm::hmi::GcodeOptions options;
  options.start_mm = machine.position;
  const edm::hmi::GcodeResult g = edm::hmi::interpret_gcode(text, part, machine.tables, options);
  if (!g.ok()) {
    for (const std::string& m : g.messages()) std::fprintf(stderr, "%s\n", m.c_str());
    return kExitBadInput;
  }
  if (!quiet) {
    std::fprintf(stderr,
                 "edmhmi: %s: %zu blocks (%d drilling, %.3f mm, estimated electrode wear %.3f "
                 "mm) → %s at %s:%u\n",
                 part.c_str(), g.blocks.size(), g.drill_blocks, g.drill_depth_mm,
                 g.electrode_wear_mm, machine.name.c_str(), settings.host.c_str(),
                 unsigned{settings.port});
  }

  edm::hmi::RunRequest req;
  req.part = part;
  req.machine = machine.name;
  req.blocks = g.blocks;
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
    case RunOutcome::kAborted:
      break;
  }
  std::fputs(edm::hmi::format_report(r.report).c_str(), stdout);
  std::fflush(stdout);
  if (r.outcome == RunOutcome::kInterrupted) return kExitInterrupted;
  // Warnings (e.g. a watchdog warning on a loaded PC) are reported; a fault alarm fails the run.
  return r.outcome == RunOutcome::kFinished && r.report.fault_alarms == 0 ? kExitOk : kExitFailure;
}

}  // namespace edmhmi
