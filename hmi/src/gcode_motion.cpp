// G-code interpreter: axis words → motion blocks in machine coordinates (docs/gcode.md "Work
// offsets", "Motion", "Drilling blocks"). Absolute words are work coordinates: machine = word +
// frame offset + G92 offset; incremental words and I/J are distances, the same in both.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "edm/machining/wear_precomp.hpp"
#include "gcode_interpreter.hpp"

namespace edm::hmi::detail {

using machining::Condition;
using machining::MotionBlock;
using machining::MotionKind;
using machining::Vec3;

namespace {

constexpr double kEps = 1e-9;            // mm: "no motion" on an axis
constexpr double kFullCircleEps = 1e-6;  // mm: an arc ending this close to its start is full
constexpr double kZeroRadius = 1e-6;     // mm

double& axis_of(Vec3& v, char axis) { return axis == 'X' ? v.x : axis == 'Y' ? v.y : v.z; }
double axis_of(const Vec3& v, char axis) { return axis == 'X' ? v.x : axis == 'Y' ? v.y : v.z; }

}  // namespace

MotionBlock Interpreter::make(MotionKind kind, const Block& b, const Word* at) const {
  MotionBlock mb{};
  mb.kind = kind;
  mb.line = b.line;
  mb.col = at != nullptr ? at->col : (b.first != nullptr ? b.first->col : 1);
  mb.target = pos_;
  mb.condition = armed_;
  mb.electrode_ref_mm = opt_.offsets.z_electrode_mm[static_cast<std::size_t>(frame_)];
  return mb;
}

void Interpreter::push(const MotionBlock& mb) {
  if (comp_.pending()) {  // emitted after the move the wire offset holds back, and its corner
    comp_.hold(mb);
    return;
  }
  push_now(mb);
}

void Interpreter::push_move(const MotionBlock& mb, const Vec3& start) {
  if (!comp_.engaged()) {
    push(mb);
    return;
  }
  std::vector<MotionBlock> out;
  if (auto e = comp_.move({mb, start}, out)) {
    error(e->line, e->col, e->message);
    return;
  }
  for (const MotionBlock& b : out) push_now(b);
}

void Interpreter::push_now(const MotionBlock& mb) {
  const Vec3 from = result_.blocks.empty() ? opt_.start_mm : result_.blocks.back().target;
  if (mb.cut) {
    ++result_.cut_blocks;
    if (mb.kind == MotionKind::kLinear) {
      result_.cut_length_mm += std::hypot(mb.target.x - from.x, mb.target.y - from.y);
    } else {
      const double r = std::hypot(from.x - mb.centre.x, from.y - mb.centre.y);
      double sweep = std::atan2(mb.target.y - mb.centre.y, mb.target.x - mb.centre.x) -
                     std::atan2(from.y - mb.centre.y, from.x - mb.centre.x);
      const double turn = 2.0 * std::numbers::pi;
      if (mb.kind == MotionKind::kArcCw) sweep = -sweep;
      while (sweep <= 1e-12) sweep += turn;
      result_.cut_length_mm += r * (sweep + turn * mb.turns);
    }
  }
  result_.blocks.push_back(mb);
  result_.frames.push_back(
      {.frame = static_cast<std::uint8_t>(frame_), .offset_mm = offset(), .g92 = g92_active_});
}

Vec3 Interpreter::offset() const noexcept {
  const Vec3& f = opt_.offsets.frame[static_cast<std::size_t>(frame_)];
  return {f.x + g92_.x, f.y + g92_.y, f.z + g92_.z};
}

/// G92 X.. Y.. Z..: the named axes' offsets are set so that the current point reads the given
/// values (always absolute, also under G91); the other axes keep theirs (LinuxCNC).
void Interpreter::set_g92(const Block& b) {
  const Vec3& f = opt_.offsets.frame[static_cast<std::size_t>(frame_)];
  for (char axis : {'X', 'Y', 'Z'}) {
    if (const Word* w = b[axis]; w != nullptr) {
      axis_of(g92_, axis) = axis_of(pos_, axis) - axis_of(f, axis) - w->value;
    }
  }
  g92_active_ = g92_.x != 0.0 || g92_.y != 0.0 || g92_.z != 0.0;
}

void Interpreter::do_orbit(const Block& b) {
  const double r = b['R']->value;
  MotionBlock mb = make(MotionKind::kOrbitFinish, b, b.nonmodal_g);
  mb.centre = pos_;
  mb.final_radius_mm = r;
  if (need_feed(b, b.nonmodal_g, "G160")) mb.feed_mm_s = feed_mm_min_ / 60.0;
  push(mb);
}

void Interpreter::do_motion(const Block& b) {
  const bool inc = incremental_;
  const Vec3 off = offset();
  auto coord = [&](char axis, double current) {
    const Word* w = b[axis];
    if (w == nullptr) return current;
    return inc ? current + w->value : w->value + axis_of(off, axis);
  };
  const Vec3 start = pos_;
  const Vec3 target{coord('X', start.x), coord('Y', start.y), coord('Z', start.z)};
  const Word* at = b.motion_g != nullptr ? b.motion_g : b.first_axis();
  if (at == nullptr) at = b['I'] != nullptr ? b['I'] : b['J'];
  remember_axis_words(b);
  switch (mode_) {
    case Motion::kRapid: {
      if (comp_.engaged()) {
        error(b, at, "G00 while the wire offset is on: cut with G01, or switch it off with G40");
        return;
      }
      pos_ = target;
      push(make(MotionKind::kRapid, b, at));
      break;
    }
    case Motion::kLinear: do_linear(b, at, start, target); break;
    case Motion::kArcCw:
    case Motion::kArcCcw: do_arc(b, at, start, target); break;
    case Motion::kNone: break;  // refused in phase 1
  }
}

void Interpreter::do_linear(const Block& b, const Word* at, const Vec3& start, const Vec3& target) {
  pos_ = target;
  if (tables_.kind == machining::MachineKind::kWire) {  // a wire cuts in XY; Z is the guide
    MotionBlock mb = make(MotionKind::kLinear, b, at);
    if (need_feed(b, at, "G01")) mb.feed_mm_s = feed_mm_min_ / 60.0;
    mb.cut = armed_ >= 1;
    if ((mb.cut || comp_.engaged()) && std::fabs(target.z - start.z) > kEps) {
      error(b, b['Z'] != nullptr ? b['Z'] : at,
            "a wire cut moves X and Y only (Z is the upper guide): move Z with E0 or G40 first");
      return;
    }
    push_move(mb, start);
    return;
  }
  const bool drill = armed_ >= 1 && target.z < start.z - kEps;
  MotionBlock mb = make(drill ? MotionKind::kDrill : MotionKind::kLinear, b, at);
  if (need_feed(b, at, "G01")) mb.feed_mm_s = feed_mm_min_ / 60.0;
  if (!drill) {
    push(mb);
    return;
  }
  for (char axis : {'X', 'Y'}) {
    const double d = axis == 'X' ? target.x - start.x : target.y - start.y;
    if (std::fabs(d) > kEps) {
      error(b, b[axis],
            "a drilling block (G01 toward -Z with E" + std::to_string(armed_) +
                " armed) must not move X or Y: drill straight, then move");
      return;
    }
  }
  pos_ = start;  // the runtime retracts out of the hole and returns to the block's start
  // The work surface is Z0 of the active frame (with G92): depths and the wear are measured from
  // there, not from machine Z 0.
  const double surface_z = offset().z;
  const double depth = surface_z - target.z;
  if (!(depth > kEps)) {
    error(b, b['Z'] != nullptr ? b['Z'] : at,
          "a drilling block must end below the work surface (Z0 of " + frame_name(frame_) +
              (g92_active_ ? " with G92" : "") + "): it ends at Z " + mm(target.z - surface_z));
    return;
  }
  const Condition* c = tables_.condition(armed_);
  const double lz = start.z - target.z;
  // Eq. (9)-(11): wear is planned for the depth eroded, below the work surface.
  const double lz_cut = std::max(0.0, std::min(start.z, surface_z) - target.z);
  const machining::WearPrecomp wp = machining::wear_precompensate(
      lz_cut, c != nullptr ? c->wear_ratio : 0.0, c != nullptr ? c->area_ratio : 1.0);
  mb.z_travel_mm = lz + wp.delta_mm;
  mb.depth_mm = depth;
  push(mb);
  result_.drill_depth_mm += lz_cut;
  result_.electrode_wear_mm += wp.delta_mm;
  ++result_.drill_blocks;
}

void Interpreter::do_arc(const Block& b, const Word* at, const Vec3& start, Vec3 target) {
  pos_ = target;
  const char* name = mode_ == Motion::kArcCw ? "G02" : "G03";
  if (std::fabs(target.z - start.z) > kEps) {
    error(b, b['Z'],
          std::string("helical arcs are not supported: Z must not change in a ") + name + " block");
    return;
  }
  const double i = b['I'] != nullptr ? b['I']->value : 0.0;
  const double j = b['J'] != nullptr ? b['J']->value : 0.0;
  const Vec3 centre{start.x + i, start.y + j, start.z};
  const double r0 = std::hypot(start.x - centre.x, start.y - centre.y);
  const double r1 = std::hypot(target.x - centre.x, target.y - centre.y);
  if (r0 < kZeroRadius) {
    error(b, at, std::string(name) + " arc radius is zero (I and J put the centre on the start)");
    return;
  }
  const double tol = std::max(opt_.arc_tolerance_mm, opt_.arc_tolerance_rel * r0);
  if (std::fabs(r1 - r0) > tol) {
    error(b, at,
          std::string(name) + " end point is not on the arc's circle: start radius " + mm(r0) +
              " mm, end radius " + mm(r1) + " mm (tolerance " + mm(tol) + " mm)");
    return;
  }
  const bool full = std::hypot(target.x - start.x, target.y - start.y) <= kFullCircleEps;
  if (full) {
    target.x = start.x;
    target.y = start.y;
    pos_ = target;
  }
  MotionBlock mb = make(mode_ == Motion::kArcCw ? MotionKind::kArcCw : MotionKind::kArcCcw, b, at);
  mb.centre = centre;
  mb.turns = b['P'] != nullptr ? static_cast<std::int32_t>(b['P']->value) : 0;
  if (need_feed(b, at, name)) mb.feed_mm_s = feed_mm_min_ / 60.0;
  if (tables_.kind == machining::MachineKind::kWire) {
    mb.cut = armed_ >= 1;
    if (comp_.engaged() && mb.turns > 0) {
      error(b, b['P'], "extra turns (P) are not compensated by the wire offset");
      return;
    }
    push_move(mb, start);
    return;
  }
  push(mb);
}

/// Where this line's X, Y and Z words are (columns, 0 = absent), for soft-limit messages.
void Interpreter::remember_axis_words(const Block& b) {
  const auto line = static_cast<std::size_t>(b.line);
  if (axis_cols_.size() <= line) axis_cols_.resize(std::max(line + 1, 2 * axis_cols_.size()));
  for (char axis : {'X', 'Y', 'Z'}) {
    axis_cols_[line][axis_index(axis)] = b[axis] != nullptr ? b[axis]->col : 0;
  }
}

}  // namespace edm::hmi::detail
