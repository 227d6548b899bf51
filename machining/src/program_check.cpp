#include "edm/machining/program_check.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace edm::machining {
namespace {

bool finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string fmt_mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

class Checker {
 public:
  Checker(const MachineTables& tables, const ProgramCheckOptions& options,
          std::vector<ProgramIssue>& out)
      : tables_(tables), options_(options), out_(out) {}

  void issue(std::size_t i, const MotionBlock& b, std::string message) {
    out_.push_back({i, b.line, b.col, std::move(message)});
  }

  void check_point(std::size_t i, const MotionBlock& b, const Vec3& p, const char* what) {
    check_axis(i, b, 'X', p.x, what);
    check_axis(i, b, 'Y', p.y, what);
    check_axis(i, b, 'Z', p.z, what);
  }

  void check_axis(std::size_t i, const MotionBlock& b, char axis, double v, const char* what) {
    const AxisLimits* a = tables_.axis(axis);
    if (a == nullptr) return;
    if (v < a->min_mm || v > a->max_mm) {
      issue(i, b,
            std::string(what) + " " + axis + " " + fmt_mm(v) + " mm is outside the soft limits [" +
                fmt_mm(a->min_mm) + ", " + fmt_mm(a->max_mm) + "]");
    }
  }

  // The arc's extreme points: the axis-aligned bounding box of the swept angle.
  void check_arc(std::size_t i, const MotionBlock& b, const Vec3& from) {
    const double r0 = std::hypot(from.x - b.centre.x, from.y - b.centre.y);
    const double r1 = std::hypot(b.target.x - b.centre.x, b.target.y - b.centre.y);
    if (!(r0 > 0.0)) {
      issue(i, b, "arc of zero radius (the centre is the start point)");
      return;
    }
    if (std::abs(r0 - r1) > std::max(options_.arc_tolerance_mm, 1e-4 * r0)) {
      issue(i, b,
            "arc start radius " + fmt_mm(r0) + " mm and end radius " + fmt_mm(r1) +
                " mm differ by more than the tolerance");
    }
    const double pi = std::numbers::pi;
    const double a0 = std::atan2(from.y - b.centre.y, from.x - b.centre.x);
    const double a1 = std::atan2(b.target.y - b.centre.y, b.target.x - b.centre.x);
    const bool ccw = b.kind == MotionKind::kArcCcw;
    double sweep = ccw ? a1 - a0 : a0 - a1;
    while (sweep <= 1e-12) sweep += 2.0 * pi;  // an arc to its own start is a full circle
    if (b.turns > 0) sweep = 2.0 * pi;         // more turns visit every angle
    for (int q = 0; q < 4; ++q) {
      const double ang = q * pi / 2.0;  // the four axis directions
      double d = ccw ? ang - a0 : a0 - ang;
      d = std::fmod(std::fmod(d, 2.0 * pi) + 2.0 * pi, 2.0 * pi);
      if (d <= sweep) {
        const Vec3 p{b.centre.x + r0 * std::cos(ang), b.centre.y + r0 * std::sin(ang), b.target.z};
        check_point(i, b, p, "arc extreme");
      }
    }
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
    switch (b.kind) {
      case MotionKind::kRapid:
      case MotionKind::kLinear:
        c.check_point(i, b, b.target, "end point");
        pos = b.target;
        break;
      case MotionKind::kArcCw:
      case MotionKind::kArcCcw:
        if (b.turns < 0) c.issue(i, b, "negative number of turns");
        c.check_point(i, b, b.target, "end point");
        c.check_arc(i, b, pos);
        pos = b.target;
        break;
      case MotionKind::kDrill:
        if (b.target.z >= pos.z) c.issue(i, b, "a drilling block must move Z down (toward -Z)");
        if (b.target.x != pos.x || b.target.y != pos.y) {
          c.issue(i, b, "a drilling block must not move X or Y");
        }
        if (!(b.z_travel_mm > 0.0)) c.issue(i, b, "a drilling block needs a positive Z travel");
        if (b.condition < 1) c.issue(i, b, "drilling needs an armed machining condition (E1..)");
        c.check_point(i, b, b.target, "hole bottom");
        {
          const Vec3 travel_end{pos.x, pos.y, pos.z - b.z_travel_mm};
          c.check_point(i, b, travel_end, "wear-compensated Z travel end");
        }
        pos = b.target;
        break;
      case MotionKind::kOrbitFinish:
        if (!(b.final_radius_mm > 0.0)) c.issue(i, b, "orbit finishing needs a final radius > 0");
        if (b.condition < 1) c.issue(i, b, "orbit finishing needs an armed machining condition");
        c.check_point(i, b, Vec3{pos.x + b.final_radius_mm, pos.y + b.final_radius_mm, pos.z},
                      "orbit extreme");
        c.check_point(i, b, Vec3{pos.x - b.final_radius_mm, pos.y - b.final_radius_mm, pos.z},
                      "orbit extreme");
        break;
      case MotionKind::kDwell:
        if (b.dwell_s < 0.0 || b.dwell_s > options.max_dwell_s) {
          c.issue(i, b, "dwell must be within [0, " + fmt_mm(options.max_dwell_s) + "] s");
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
      case MotionKind::kFlushing:
        break;
      case MotionKind::kEnd:
        ended = true;
        break;
    }
    if (b.kind != MotionKind::kCondition && b.condition > 0 &&
        tables.condition(b.condition) == nullptr) {
      c.issue(i, b, "unknown machining condition E" + std::to_string(b.condition));
    }
  }
  return out;
}

}  // namespace edm::machining
