#include "edm/machining/program_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace edm::machining {
namespace {

constexpr double kLimitSlackMm = 1e-9;  // rounding slack: a point this close to a limit is in

bool finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string mm(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

/// The angle swept (rad, in (0, 2π]) going from angle a0 to a1 counter-clockwise; equal angles
/// sweep the full circle.
double ccw_sweep(double a0, double a1) noexcept {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double s = std::fmod(a1 - a0, kTwoPi);
  if (s <= 0.0) s += kTwoPi;
  return s;
}

/// Bounding box of an XY arc relative to its centre (mm).
struct ArcBox {
  double min_x{0.0};
  double max_x{0.0};
  double min_y{0.0};
  double max_y{0.0};
};

/// The box of the arc from (sx, sy) to (ex, ey) (both relative to the centre) swept clockwise or
/// counter-clockwise; `full` sweeps the whole circle (extra turns). The radius is the start
/// radius (the end radius agrees within the arc tolerance).
ArcBox arc_bounding_box(double sx, double sy, double ex, double ey, bool clockwise,
                        bool full) noexcept {
  const double r = std::hypot(sx, sy);
  ArcBox box{std::min(sx, ex), std::max(sx, ex), std::min(sy, ey), std::max(sy, ey)};
  const double a0 = std::atan2(sy, sx);
  const double a1 = std::atan2(ey, ex);
  // Going clockwise from a0 to a1 sweeps the same points as counter-clockwise from a1 to a0.
  const double from = clockwise ? a1 : a0;
  const double sweep = full ? 2.0 * std::numbers::pi : ccw_sweep(from, clockwise ? a0 : a1);
  for (int k = 0; k < 4; ++k) {
    const double a = k * std::numbers::pi / 2.0;
    // An axis direction a lies on the arc when it is reached from `from` within the sweep.
    if (full || ccw_sweep(from, a) <= sweep) {
      switch (k) {
        case 0: box.max_x = std::max(box.max_x, r); break;
        case 1: box.max_y = std::max(box.max_y, r); break;
        case 2: box.min_x = std::min(box.min_x, -r); break;
        default: box.min_y = std::min(box.min_y, -r); break;
      }
    }
  }
  return box;
}

class Checker {
 public:
  Checker(const MachineTables& tables, const ProgramCheckOptions& options,
          std::vector<ProgramIssue>& out)
      : tables_(tables), options_(options), out_(out) {}

  void issue(std::size_t i, const MotionBlock& b, std::string message) {
    out_.push_back({i, b.line, b.col, std::move(message)});
  }

  /// The limits of `axis` when v is beyond them, else nullptr.
  [[nodiscard]] const AxisLimits* beyond(char axis, double v) const {
    const AxisLimits* a = tables_.axis(axis);
    if (a == nullptr || (v >= a->min_mm - kLimitSlackMm && v <= a->max_mm + kLimitSlackMm)) {
      return nullptr;
    }
    return a;
  }

  /// Each coordinate of p beyond its axis's limits; `extent` names an arc's or orbit's extent
  /// ("G02 arc: "), empty for an end point (then the issue names its axis).
  void check_point(std::size_t i, const MotionBlock& b, const Vec3& p, const std::string& extent,
                   bool with_z = true) {
    check_axis(i, b, 'X', p.x, extent);
    check_axis(i, b, 'Y', p.y, extent);
    if (with_z) check_axis(i, b, 'Z', p.z, extent);
  }

  void check_axis(std::size_t i, const MotionBlock& b, char axis, double v,
                  const std::string& extent) {
    if (const AxisLimits* a = beyond(axis, v)) {
      limit_issue(i, b, extent.empty() ? axis : '\0',
                  extent + axis + " " + mm(v) + " mm is beyond the " + axis + " soft limit (" +
                      mm(a->min_mm) + ".." + mm(a->max_mm) + " mm)");
    }
  }

  void limit_issue(std::size_t i, const MotionBlock& b, char axis, std::string message) {
    out_.push_back({i, b.line, b.col, std::move(message), true, axis});
  }

  /// Arc consistency, then the arc's extent over its swept angle (which holds its end point).
  void check_arc(std::size_t i, const MotionBlock& b, const Vec3& from) {
    const double r0 = std::hypot(from.x - b.centre.x, from.y - b.centre.y);
    const double r1 = std::hypot(b.target.x - b.centre.x, b.target.y - b.centre.y);
    if (!(r0 > 0.0)) {
      issue(i, b, "arc of zero radius (the centre is the start point)");
      return;
    }
    if (std::abs(r0 - r1) > std::max(options_.arc_tolerance_mm, 1e-4 * r0)) {
      issue(i, b,
            "arc start radius " + mm(r0) + " mm and end radius " + mm(r1) +
                " mm differ by more than the tolerance");
    }
    const bool cw = b.kind == MotionKind::kArcCw;
    const ArcBox box =
        arc_bounding_box(from.x - b.centre.x, from.y - b.centre.y, b.target.x - b.centre.x,
                         b.target.y - b.centre.y, cw, b.turns > 0);
    const std::string extent = std::string(cw ? "G02" : "G03") + " arc: ";
    check_point(i, b, {b.centre.x + box.min_x, b.centre.y + box.min_y, from.z}, extent);
    check_point(i, b, {b.centre.x + box.max_x, b.centre.y + box.max_y, from.z}, extent, false);
  }

  /// The Z axis of a drilling block travels the wear-compensated z_travel_mm (eq. 9-11), past
  /// the nominal bottom; reported when the bottom itself is inside (else the end point says it).
  /// `to`: the block's end where the job puts it (electrode length compensation included).
  void check_drill_travel(std::size_t i, const MotionBlock& b, const Vec3& from, const Vec3& to) {
    const AxisLimits* z = tables_.axis('Z');
    const double axis_end = from.z - b.z_travel_mm;
    if (z == nullptr || beyond('Z', to.z) != nullptr || beyond('Z', axis_end) == nullptr) {
      return;
    }
    const double wear = b.z_travel_mm - (from.z - to.z);
    limit_issue(i, b, 'Z',
                "drilling with wear pre-compensation moves Z to " + mm(axis_end) + " mm (nominal " +
                    mm(to.z) + " - wear " + mm(wear) + " mm), beyond the Z soft limit (" +
                    mm(z->min_mm) + ".." + mm(z->max_mm) + " mm)");
  }

 private:
  const MachineTables& tables_;
  const ProgramCheckOptions& options_;
  std::vector<ProgramIssue>& out_;
};

}  // namespace

std::vector<ProgramIssue> check_program(std::span<const MotionBlock> program,
                                        const MachineTables& tables, const Vec3& start,
                                        const ProgramCheckOptions& options) {
  std::vector<ProgramIssue> out;
  if (program.empty()) {
    out.push_back({0, 0, 0, "the program has no blocks"});
    return out;
  }
  if (program.size() > options.max_blocks) {
    out.push_back({options.max_blocks, 0, 0,
                   "the program has " + std::to_string(program.size()) + " blocks, more than " +
                       std::to_string(options.max_blocks)});
    return out;
  }
  Checker c(tables, options, out);
  Vec3 pos = start;
  bool ended = false;
  for (std::size_t i = 0; i < program.size(); ++i) {
    const MotionBlock& b = program[i];
    if (ended) {
      c.issue(i, b, "block after the end of the program (M02/M30)");
      break;
    }
    if (static_cast<int>(b.kind) >= kMotionKindCount) {
      c.issue(i, b, "unknown block kind " + std::to_string(static_cast<int>(b.kind)));
      continue;
    }
    if (!finite(b.target) || !finite(b.centre) || !std::isfinite(b.feed_mm_s) ||
        !std::isfinite(b.z_travel_mm) || !std::isfinite(b.final_radius_mm) ||
        !std::isfinite(b.dwell_s)) {
      c.issue(i, b, "a number in the block is not finite");
      continue;
    }
    if (b.feed_mm_s < 0.0) c.issue(i, b, "negative feed");
    // Where the job puts the block: Z shifted by the length the electrode lost since the block's
    // work frame was set (EdmJob compensates rapids and feeds; arcs keep that Z and a drill goes
    // its travel down from it, so their ends shift alike).
    Vec3 end = b.target;
    if (options.electrode_mm > 0.0 && b.electrode_ref_mm > 0.0) {
      end.z += options.electrode_mm - b.electrode_ref_mm;
    }
    switch (b.kind) {
      case MotionKind::kRapid:
      case MotionKind::kLinear:
        c.check_point(i, b, end, "");
        pos = end;
        break;
      case MotionKind::kArcCw:
      case MotionKind::kArcCcw:
        if (b.turns < 0) c.issue(i, b, "negative number of turns");
        c.check_arc(i, b, pos);
        pos = end;
        break;
      case MotionKind::kDrill:
        if (end.z >= pos.z) c.issue(i, b, "a drilling block must move Z down (toward -Z)");
        if (end.x != pos.x || end.y != pos.y) {
          c.issue(i, b, "a drilling block must not move X or Y");
        }
        if (!(b.z_travel_mm > 0.0)) c.issue(i, b, "a drilling block needs a positive Z travel");
        if (b.condition < 1) c.issue(i, b, "drilling needs an armed machining condition (E1..)");
        c.check_point(i, b, end, "");
        c.check_drill_travel(i, b, pos, end);
        pos = end;
        break;
      case MotionKind::kOrbitFinish:
        if (!(b.final_radius_mm > 0.0)) c.issue(i, b, "orbit finishing needs a final radius > 0");
        if (b.condition < 1) c.issue(i, b, "orbit finishing needs an armed machining condition");
        if (b.final_radius_mm > 0.0) {
          const double r = b.final_radius_mm;
          const std::string extent = "G160 orbit of radius " + mm(r) + " mm: ";
          c.check_point(i, b, Vec3{pos.x - r, pos.y - r, pos.z}, extent, false);
          c.check_point(i, b, Vec3{pos.x + r, pos.y + r, pos.z}, extent, false);
        }
        break;
      case MotionKind::kDwell:
        if (b.dwell_s < 0.0 || b.dwell_s > options.max_dwell_s) {
          c.issue(i, b, "dwell must be within [0, " + mm(options.max_dwell_s) + "] s");
        }
        break;
      case MotionKind::kCondition:
        if (b.condition < 0) {
          c.issue(i, b, "negative condition number");
        } else if (b.condition > 0 && tables.condition(b.condition) == nullptr) {
          c.issue(i, b, "unknown machining condition E" + std::to_string(b.condition));
        }
        break;
      case MotionKind::kRotation:
      case MotionKind::kFlushing: break;
      case MotionKind::kProgramStop: break;
      case MotionKind::kEnd: ended = true; break;
    }
    if (b.kind != MotionKind::kCondition && b.condition > 0 &&
        tables.condition(b.condition) == nullptr) {
      c.issue(i, b, "unknown machining condition E" + std::to_string(b.condition));
    }
  }
  return out;
}

}  // namespace edm::machining
