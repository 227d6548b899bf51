#include "edm/hmi/job_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

namespace edm::hmi {

namespace {

using machining::MotionKind;

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string percent(const std::optional<double>& f) {
  return f ? fmt("%.2f %%", *f * 100.0) : std::string("n/a");
}

/// A coordinate that rounds to 0 at 4 decimals prints as 0, not -0.
double tidy(double mm) { return std::fabs(mm) < 5e-5 ? 0.0 : mm; }

std::string xyz(const machining::Vec3& v) { return format_xyz(v); }

std::string xy(const machining::Vec3& v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "X %.4f Y %.4f", tidy(v.x), tidy(v.y));
  return buf;
}

/// The work frame, the holes and the end position, in work and machine coordinates. Without the
/// program's frames (`edmhmi status` after a restart) only the machine's end position.
template <class Row>
void position_rows(const JobReport& r, Row&& row) {
  const std::optional<BlockFrame>& frame = r.targets.end_frame;
  if (frame) {
    row("work frame", frame_name(frame->frame) + (frame->g92 ? " + G92" : "") + ", origin at " +
                          xyz(frame->offset_mm) + " machine");
  }
  const std::vector<HolePosition>& holes = r.targets.holes;
  for (std::size_t i = 0; i < holes.size() && i < kReportHoles; ++i) {
    const HolePosition& h = holes[i];
    row("hole (line " + std::to_string(h.line) + ")", xy(h.work_mm) + " " + frame_name(h.frame) +
                                                          " = " + xy(h.machine_mm) + " machine, " +
                                                          fmt("%.4f mm deep", h.depth_mm));
  }
  if (holes.size() > kReportHoles) {
    row("", "... and " + std::to_string(holes.size() - kReportHoles) + " more holes");
  }
  const JobFigures& f = r.end;
  if (!f.x_mm || !f.y_mm || !f.z_mm) return;
  const machining::Vec3 machine{*f.x_mm, *f.y_mm, *f.z_mm};
  if (frame) {
    // The tip, in work coordinates (what the program says); the spindle, in machine ones.
    machining::Vec3 tip = to_work(machine, frame->offset_mm);
    tip.z -= f.z_comp_mm.value_or(0.0);
    row("end position",
        xyz(tip) + " " + frame_name(frame->frame) + " = " + xyz(machine) + " machine");
  } else {
    row("end position", xyz(machine) + " machine");
  }
}

}  // namespace

std::string format_xyz(const machining::Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "X %.4f Y %.4f Z %.4f", tidy(v.x), tidy(v.y), tidy(v.z));
  return buf;
}

std::optional<double> JobFigures::short_fraction() const {
  if (!pulses || !shorts || *pulses <= 0.0) return std::nullopt;
  return *shorts / *pulses;
}

std::optional<double> JobFigures::arc_fraction() const {
  if (!pulses || !arcs || *pulses <= 0.0) return std::nullopt;
  return *arcs / *pulses;
}

JobFigures figures_from_status(const bridge::StatusMessage& s) {
  JobFigures f;
  struct Key {
    std::string_view suffix;
    std::optional<double> JobFigures::*field;
  };
  static constexpr Key kKeys[] = {
      {".job_time_s", &JobFigures::time_s},     {".job_pulses", &JobFigures::pulses},
      {".job_shorts", &JobFigures::shorts},     {".job_arcs", &JobFigures::arcs},
      {".job_depth_mm", &JobFigures::depth_mm}, {".job_wear_mm", &JobFigures::wear_mm},
  };
  static constexpr Key kIo[] = {
      {"io.depth_mm", &JobFigures::hole_depth_mm},
      {"io.electrode_mm", &JobFigures::electrode_mm},
      {"io.wall_radius_mm", &JobFigures::wall_radius_mm},
      {"io.x_mm", &JobFigures::x_mm},
      {"io.y_mm", &JobFigures::y_mm},
      {"io.z_mm", &JobFigures::z_mm},
      {"cnc.job.z_comp_mm", &JobFigures::z_comp_mm},
  };
  for (const auto& [name, value] : s.vars) {
    if (!std::isfinite(value)) continue;
    for (const Key& k : kKeys) {
      if (ends_with(name, k.suffix)) f.*k.field = value;
    }
    for (const Key& k : kIo) {
      if (name == k.suffix) f.*k.field = value;
    }
  }
  return f;
}

double drill_depth_of(const machining::MotionBlock& b) noexcept {
  return b.depth_mm > 0.0 ? b.depth_mm : -b.target.z;
}

ProgramTargets program_targets(const std::vector<machining::MotionBlock>& blocks) {
  ProgramTargets t;
  t.blocks = blocks.size();
  for (const auto& b : blocks) {
    if (b.kind == MotionKind::kDrill)
      t.deepest_drill_mm = std::max(t.deepest_drill_mm, drill_depth_of(b));
    if (b.kind == MotionKind::kOrbitFinish) {
      t.largest_radius_mm = std::max(t.largest_radius_mm, b.final_radius_mm);
    }
  }
  return t;
}

ProgramTargets program_targets(const std::vector<machining::MotionBlock>& blocks,
                               const std::vector<BlockFrame>& frames) {
  ProgramTargets t = program_targets(blocks);
  if (frames.size() != blocks.size() || blocks.empty()) return t;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const machining::MotionBlock& b = blocks[i];
    if (b.kind != MotionKind::kDrill) continue;
    t.holes.push_back({.line = b.line,
                       .machine_mm = b.target,
                       .work_mm = to_work(b.target, frames[i].offset_mm),
                       .frame = frames[i].frame,
                       .depth_mm = drill_depth_of(b)});
  }
  t.end_frame = frames.back();
  return t;
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  const auto total = static_cast<long long>(std::llround(seconds));
  char buf[32];
  if (total >= 3600) {
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", total / 3600, (total / 60) % 60,
                  total % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lld:%02lld", total / 60, total % 60);
  }
  return buf;
}

std::string format_progress(const ProgressView& v, int bar_width) {
  const bool drilling = v.kind == MotionKind::kDrill && v.drill_target_mm > 0.0;
  double fraction = 0.0;
  std::string what;
  if (drilling) {
    const double depth = v.figures.depth_mm.value_or(0.0);
    fraction = depth / v.drill_target_mm;
    what = fmt("depth %7.3f", depth) + fmt(" / %.3f mm", v.drill_target_mm);
  } else if (v.blocks > 0) {
    fraction = static_cast<double>(v.block) / static_cast<double>(v.blocks);
  }
  const bool finished = v.outcome == "finished";  // its end block is the last index, not N
  if (finished) fraction = 1.0;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(std::lround(fraction * bar_width));
  std::string line = "[" + std::string(static_cast<std::size_t>(filled), '#') +
                     std::string(static_cast<std::size_t>(bar_width - filled), '.') + "] ";
  line += fmt("%3.0f%% ", fraction * 100.0);
  if (!what.empty()) line += what + "  ";
  line += "block " + std::to_string(std::min(v.block + 1, std::max<std::uint64_t>(v.blocks, 1))) +
          "/" + std::to_string(v.blocks) + " (line " + std::to_string(v.line) + " " +
          std::string(machining::to_string(v.kind)) + ")  ";
  line += format_duration(v.elapsed_s) + " elapsed";
  line += "  ETA " + (finished  ? format_duration(0.0)
                      : v.eta_s ? format_duration(*v.eta_s)
                                : std::string("--:--"));
  line += "  " + v.state;
  if (const auto sf = v.figures.short_fraction()) line += fmt("  short %.2f%%", *sf * 100.0);
  return line;
}

void fill_from_status(JobReport& r, const bridge::StatusMessage& s) {
  r.outcome = s.job_outcome;
  r.state = s.state;
  r.cause = s.state == "FAULT" || s.state == "ESTOP" ? s.cause : 0;
  r.blocks_done = s.job_outcome == "finished" ? s.job_blocks  // the end block included
                                              : std::min(s.job_block, s.job_blocks);
  r.end = figures_from_status(s);
}

std::string format_report(const JobReport& r) {
  std::string out;
  // The longest label ("wall radius (measured)", 22) still gets two spaces before its value.
  auto row = [&out](std::string_view label, const std::string& value) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "  %-24s", std::string(label).c_str());
    out += buf + value + "\n";
  };
  out += "job report: " + r.part + (r.machine.empty() ? "" : " on " + r.machine) + "\n";
  std::string outcome = r.outcome + (r.dry_run ? " (dry run)" : "");
  if (r.cause != 0) outcome += " (machine " + r.state + ", alarm " + std::to_string(r.cause) + ")";
  row("outcome", outcome);
  row("blocks", std::to_string(r.blocks_done) + " of " + std::to_string(r.targets.blocks));
  const JobFigures& f = r.end;
  row("machining time",
      f.time_s ? format_duration(*f.time_s) + fmt(" (%.1f s)", *f.time_s) : std::string("n/a"));
  if (r.targets.deepest_drill_mm > 0.0 && r.dry_run) {
    // The generator never armed and the drilling blocks were skipped: there is no hole to judge.
    row("depth reached",
        fmt("not drilled: a dry run (program %.4f mm)", r.targets.deepest_drill_mm));
  } else if (r.targets.deepest_drill_mm > 0.0) {
    std::string depth = f.depth_mm ? fmt("%.4f mm", *f.depth_mm) : std::string("n/a");
    depth += fmt(" (program %.4f mm", r.targets.deepest_drill_mm);
    if (f.depth_mm) depth += fmt(", error %+.4f mm", *f.depth_mm - r.targets.deepest_drill_mm);
    row("depth reached", depth + ")");
    if (f.hole_depth_mm) row("hole depth (measured)", fmt("%.4f mm", *f.hole_depth_mm));
  } else if (f.depth_mm && *f.depth_mm > 0.0) {
    // The program is not known (`edmhmi status` after a restart): the machine's figures alone.
    row("depth reached", fmt("%.4f mm", *f.depth_mm));
    if (f.hole_depth_mm) row("hole depth (measured)", fmt("%.4f mm", *f.hole_depth_mm));
  }
  if (r.targets.largest_radius_mm > 0.0 && f.wall_radius_mm) {
    row("wall radius (measured)",
        fmt("%.4f mm", *f.wall_radius_mm) + fmt(" (program %.4f mm)", r.targets.largest_radius_mm));
  }
  std::string used = f.wear_mm ? fmt("%.3f mm estimated (eq. 8)", *f.wear_mm) : std::string("n/a");
  if (r.electrode_at_start_mm && f.electrode_mm) {
    used += fmt(", %.3f mm measured", *r.electrode_at_start_mm - *f.electrode_mm);
  }
  row("electrode used", used);
  position_rows(r, row);
  if (f.electrode_mm) row("electrode left", fmt("%.3f mm", *f.electrode_mm));
  row("pulses", f.pulses ? fmt("%.0f", *f.pulses) : std::string("n/a"));
  row("short circuits", percent(f.short_fraction()));
  row("arcs", percent(f.arc_fraction()));
  if (!r.alarms_seen) {
    // Nothing watched the job's alarms: the outcome row has the machine's last cause.
  } else if (r.alarms.empty()) {
    row("alarms", "none");
  } else {
    row("alarms", std::to_string(r.alarms.size()));
    for (const std::string& a : r.alarms) out += "    " + a + "\n";
  }
  return out;
}

}  // namespace edm::hmi
