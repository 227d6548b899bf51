// Run from a block: the re-approach prologue and the drilling block's remaining depth
// (resume.hpp, docs/gcode.md "Resuming a program").
#include "edm/hmi/resume.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "edm/hmi/job_report.hpp"
#include "edm/machining/wear_precomp.hpp"

namespace edm::hmi {

namespace {

using machining::MotionBlock;
using machining::MotionKind;
using machining::Vec3;

constexpr double kDepthTolerance = 1e-9;  // mm

std::string mm(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

ResumePlan refuse(std::string why) {
  ResumePlan p;
  p.error = std::move(why);
  return p;
}

/// The state the program had before block `first`: the armed condition, rotation, flushing.
struct Modal {
  int condition{0};
  bool rotation{false};
  bool flushing{false};
};

Modal modal_before(const std::vector<MotionBlock>& blocks, std::size_t first) {
  Modal m;
  for (std::size_t i = 0; i < first; ++i) {
    const MotionBlock& b = blocks[i];
    if (b.kind == MotionKind::kCondition) m.condition = b.condition;
    if (b.kind == MotionKind::kRotation) m.rotation = b.on;
    if (b.kind == MotionKind::kFlushing) m.flushing = b.on;
  }
  return m;
}

/// Eq. (9)-(11) for what is left of a drilling block whose hole is already `done` deep: the axis
/// still travels the whole block, the wear is planned for the depth still to erode (from the
/// hole's present bottom, or the block's start if that is lower, down to the target).
void resume_drill(MotionBlock& b, const Vec3& start, double done,
                  const machining::MachineTables& tables) {
  const double surface_z = b.target.z + drill_depth_of(b);
  const double remaining = std::max(0.0, std::min(start.z, surface_z - done) - b.target.z);
  const machining::Condition* c = tables.condition(b.condition);
  const machining::WearPrecomp wp = machining::wear_precompensate(
      remaining, c != nullptr ? c->wear_ratio : 0.0, c != nullptr ? c->area_ratio : 1.0);
  b.z_travel_mm = (start.z - b.target.z) + wp.delta_mm;
  b.depth_done_mm = done;
}

}  // namespace

std::vector<Vec3> block_starts(const GcodeResult& program) {
  std::vector<Vec3> starts;
  starts.reserve(program.blocks.size());
  Vec3 pos = program.start_mm;
  for (const MotionBlock& b : program.blocks) {
    starts.push_back(pos);
    if (b.kind != MotionKind::kDrill) pos = b.target;  // a drilling block ends where it began
  }
  return starts;
}

ResumePlan plan_resume(const GcodeResult& program, const machining::MachineTables& tables,
                       std::int32_t line, double depth_done_mm,
                       const std::optional<DrillResume>& drill_state) {
  if (!program.ok()) return refuse("the program has errors; fix them first (edmhmi check)");
  const std::vector<MotionBlock>& blocks = program.blocks;
  if (line < 1) return refuse("line " + std::to_string(line) + ": lines are numbered from 1");
  if (!std::isfinite(depth_done_mm) || depth_done_mm < 0.0) {
    return refuse("the depth already drilled must be a number >= 0 mm, not " + mm(depth_done_mm));
  }
  const auto it = std::find_if(blocks.begin(), blocks.end(),
                               [line](const MotionBlock& b) { return b.line >= line; });
  if (it == blocks.end()) {
    return refuse("line " + std::to_string(line) + " is past the program's last block (line " +
                  std::to_string(blocks.empty() ? 0 : blocks.back().line) + ")");
  }
  const auto first = static_cast<std::size_t>(it - blocks.begin());
  const std::int32_t at = it->line;
  if (it->kind == MotionKind::kEnd) {
    return refuse("line " + std::to_string(at) + " is the program end: nothing to resume");
  }
  // The blocks of the resumed line: its drilling block takes the depth; an orbit cannot resume.
  std::optional<std::size_t> drill;
  for (std::size_t i = first; i < blocks.size() && blocks[i].line == at; ++i) {
    if (blocks[i].kind == MotionKind::kOrbitFinish) {
      return refuse("line " + std::to_string(at) +
                    " is a G160 orbit-finishing cycle, which cannot be resumed part-way: resume "
                    "from an earlier line to run the cycle whole");
    }
    if (blocks[i].kind == MotionKind::kDrill && !drill) drill = i;
  }
  if (!drill && depth_done_mm > 0.0) {
    return refuse("line " + std::to_string(at) + " has no drilling block to take a depth of " +
                  mm(depth_done_mm) + " mm");
  }
  if (drill) {
    const double depth = drill_depth_of(blocks[*drill]);
    if (depth_done_mm > depth + kDepthTolerance) {
      return refuse("the hole is already " + mm(depth_done_mm) + " mm deep; line " +
                    std::to_string(at) + " drills to " + mm(depth) +
                    " mm: nothing left to drill, resume from the next line");
    }
  }

  const std::vector<Vec3> starts = block_starts(program);
  // The prologue is in the frame of the resumed block, with its electrode length reference, so
  // the job compensates it as it compensates that block (a new electrode of another length: the
  // approach ends where the block begins). Where the electrode is now, in those coordinates:
  // the spindle's Z less the compensation the job will add.
  const double ref = blocks[first].electrode_ref_mm;
  const double comp = program.electrode_mm > 0.0 && ref > 0.0 ? program.electrode_mm - ref : 0.0;
  const Vec3 now{program.start_mm.x, program.start_mm.y, program.start_mm.z - comp};
  const Vec3 target = first == 0 ? now : starts[first];
  // The highest point of the program so far is clear of the work (it got there by rapids and
  // feeds the operator wrote); so is where the electrode is now, above it. (starts[0] is the
  // spindle's start, uncompensated: `now` stands for it.)
  double clearance = std::max(now.z, target.z);
  for (std::size_t i = 1; i < first; ++i) clearance = std::max(clearance, starts[i].z);

  ResumePlan p;
  p.first = first;
  p.line = at;
  p.clearance_z_mm = clearance;
  const BlockFrame frame =
      program.frames.size() == blocks.size() ? program.frames[first] : BlockFrame{};
  const Modal modal = modal_before(blocks, first);
  auto add = [&p, &frame, ref](MotionKind kind, const Vec3& point) -> MotionBlock& {
    MotionBlock b{};
    b.kind = kind;
    b.electrode_ref_mm = ref;
    b.line = 0;  // not a line of the program: a record of an interruption here names line 0
    b.col = 0;
    b.target = point;
    p.blocks.push_back(b);
    p.frames.push_back(frame);
    return p.blocks.back();
  };
  add(MotionKind::kRapid, {now.x, now.y, clearance});
  add(MotionKind::kRapid, {target.x, target.y, clearance});
  add(MotionKind::kRapid, target);
  add(MotionKind::kRotation, target).on = modal.rotation;
  add(MotionKind::kFlushing, target).on = modal.flushing;
  MotionBlock& arm = add(MotionKind::kCondition, target);
  arm.condition = modal.condition;
  p.prologue = p.blocks.size();

  p.blocks.insert(p.blocks.end(), blocks.begin() + static_cast<std::ptrdiff_t>(first),
                  blocks.end());
  if (program.frames.size() == blocks.size()) {
    p.frames.insert(p.frames.end(), program.frames.begin() + static_cast<std::ptrdiff_t>(first),
                    program.frames.end());
  } else {
    p.frames.resize(p.blocks.size(), frame);
  }
  if (drill) {
    p.drill = p.prologue + (*drill - first);
    p.depth_done_mm = depth_done_mm;
    Vec3 drill_start = starts[*drill];
    const bool state = drill_state && depth_done_mm > 0.0 &&
                       std::isfinite(drill_state->touch_z_mm) &&
                       std::isfinite(drill_state->wear_mm) && drill_state->wear_mm > 0.0;
    if (state) {
      // Where the front stopped, from the interrupted drill's own figures (the spark-gap offset
      // left out: it only puts this a few µm higher), plus the clearance: lowered there with the
      // generator off (a feed move never discharges), the drill's first sparks are at the bottom.
      const double z_near =
          drill_state->touch_z_mm - depth_done_mm - drill_state->wear_mm + kResumeClearanceMm;
      if (z_near < drill_start.z) {
        MotionBlock down{};
        down.kind = MotionKind::kLinear;
        down.target = {drill_start.x, drill_start.y, z_near};
        down.feed_mm_s = 1.0;
        down.condition = p.blocks[*p.drill].condition;
        p.blocks.insert(p.blocks.begin() + static_cast<std::ptrdiff_t>(*p.drill), down);
        p.frames.insert(p.frames.begin() + static_cast<std::ptrdiff_t>(*p.drill), frame);
        ++*p.drill;
        drill_start.z = z_near;
      }
      MotionBlock& d = p.blocks[*p.drill];
      d.resume_touch_z_mm = drill_state->touch_z_mm;
      d.resume_wear_mm = drill_state->wear_mm;
    }
    resume_drill(p.blocks[*p.drill], drill_start, depth_done_mm, tables);
  }
  return p;
}

}  // namespace edm::hmi
