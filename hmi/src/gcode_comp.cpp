#include "gcode_comp.hpp"

// The offset path's geometry: tangents, offset lines and arcs, their intersections at inside
// corners, the arcs at outside corners.

#include <cmath>
#include <cstdio>
#include <numbers>

namespace edm::hmi::detail {

using machining::MotionBlock;
using machining::MotionKind;
using machining::Vec3;

namespace {

constexpr double kEps = 1e-9;
constexpr double kOnTol = 1e-6;  // mm: how far outside its extent an intersection may lie

struct P2 {
  double x{0.0}, y{0.0};
};
P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
P2 operator*(double k, P2 a) { return {k * a.x, k * a.y}; }
double dot(P2 a, P2 b) { return a.x * b.x + a.y * b.y; }
double cross(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }
double norm(P2 a) { return std::hypot(a.x, a.y); }
P2 xy(const Vec3& v) { return {v.x, v.y}; }
P2 left(P2 t) { return {-t.y, t.x}; }

std::string mm3(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

bool is_arc(const MotionBlock& b) {
  return b.kind == MotionKind::kArcCw || b.kind == MotionKind::kArcCcw;
}

/// The unit tangent of move m at point p on it (p: its start or end).
P2 tangent(const CompMove& m, P2 p) {
  if (!is_arc(m.b)) {
    const P2 d = xy(m.b.target) - xy(m.from);
    const double n = norm(d);
    return n > kEps ? (1.0 / n) * d : P2{1.0, 0.0};
  }
  const P2 r = p - xy(m.b.centre);
  const double n = norm(r);
  const P2 t = n > kEps ? (1.0 / n) * left(r) : P2{1.0, 0.0};  // counter-clockwise
  return m.b.kind == MotionKind::kArcCcw ? t : -1.0 * t;
}

}  // namespace

/// A move of the offset path as a whole line (through `p` along unit `u`) or circle, with the
/// extent an intersection must fall in (`a` to `b`, along the move's direction).
struct WireOffset::Element {
  bool arc{false};
  bool ccw{false};
  P2 p, u;  // line
  P2 c;     // arc centre
  double r{0.0};
  P2 a, b;  // extent: from a to b

  /// Whether q (on the line or circle) lies within the extent.
  [[nodiscard]] bool holds(P2 q) const {
    if (!arc) {
      const double len = norm(b - a);
      const double t = dot(q - a, u);
      return t >= -kOnTol && t <= len + kOnTol;
    }
    const double sweep_sign = ccw ? 1.0 : -1.0;
    auto angle_from_a = [&](P2 v) {
      double ang = std::atan2(cross(a - c, v - c), dot(a - c, v - c)) * sweep_sign;
      if (ang < -kEps) ang += 2.0 * std::numbers::pi;
      return ang;
    };
    double total = angle_from_a(b);
    if (total <= kEps) total = 2.0 * std::numbers::pi;  // a full circle
    return angle_from_a(q) <= total + kOnTol / std::max(r, kEps);
  }
};

namespace {

using Element = WireOffset::Element;

/// The intersections of two elements (lines and circles as a whole).
std::vector<P2> intersect(const Element& e, const Element& f) {
  std::vector<P2> out;
  if (!e.arc && !f.arc) {
    const double den = cross(e.u, f.u);
    if (std::fabs(den) < kEps) return out;
    const double t = cross(f.p - e.p, f.u) / den;
    out.push_back(e.p + t * e.u);
    return out;
  }
  if (e.arc != f.arc) {
    const Element& l = e.arc ? f : e;
    const Element& c = e.arc ? e : f;
    const P2 w = l.p - c.c;
    const double bq = dot(l.u, w), cq = dot(w, w) - c.r * c.r;
    const double disc = bq * bq - cq;
    if (disc < 0.0) return out;
    const double s = std::sqrt(disc);
    out.push_back(l.p + (-bq - s) * l.u);
    out.push_back(l.p + (-bq + s) * l.u);
    return out;
  }
  const P2 d = f.c - e.c;
  const double dist = norm(d);
  if (dist < kEps || dist > e.r + f.r || dist < std::fabs(e.r - f.r)) return out;
  const double a = (e.r * e.r - f.r * f.r + dist * dist) / (2.0 * dist);
  const double h = std::sqrt(std::max(0.0, e.r * e.r - a * a));
  const P2 m = e.c + (a / dist) * d;
  const P2 perp = left((1.0 / dist) * d);
  out.push_back(m + h * perp);
  out.push_back(m - h * perp);
  return out;
}

}  // namespace

void WireOffset::start(int side, double d_mm) noexcept {
  side_ = side;
  d_ = d_mm;
  lead_in_ = true;
  stopping_ = false;
}

void WireOffset::emit(const CompMove& m, Vec3 to, std::vector<MotionBlock>& out) const {
  MotionBlock b = m.b;
  b.target.x = to.x;
  b.target.y = to.y;
  out.push_back(b);
}

std::optional<CompError> WireOffset::at_end(int line, int col) const {
  if (side_ == 0) return std::nullopt;
  return CompError{line, col,
                   "the wire offset (G41/G42) is still on at the program end: end the contour "
                   "with G40 on a straight lead-out move"};
}

std::optional<CompError> WireOffset::move(const CompMove& m, std::vector<MotionBlock>& out) {
  const double s = static_cast<double>(side_);
  if ((lead_in_ || stopping_) && is_arc(m.b)) {
    return CompError{m.b.line, m.b.col,
                     std::string("the wire offset is switched ") + (lead_in_ ? "on" : "off") +
                         " on a straight " + (lead_in_ ? "lead-in" : "lead-out") +
                         " move (G01), not on an arc"};
  }
  if (is_arc(m.b)) {  // a concave arc must be larger than the offset
    const double r = norm(xy(m.from) - xy(m.b.centre));
    const double rr = m.b.kind == MotionKind::kArcCcw ? r - s * d_ : r + s * d_;
    if (!(rr > kOnTol)) {
      return CompError{m.b.line, m.b.col,
                       "the wire offset " + mm3(d_) +
                           " mm cannot be applied: this concave arc's "
                           "radius " +
                           mm3(r) + " mm is not larger than the offset"};
    }
  }
  if (lead_in_) {
    if (norm(xy(m.b.target) - xy(m.from)) <= d_) {
      return CompError{m.b.line, m.b.col,
                       "the lead-in move must be longer than the wire offset (" + mm3(d_) +
                           " mm) to switch it on"};
    }
    lead_in_ = false;
    pending_ = m;
    pending_from_ = m.from;  // the lead-in starts where the wire is
    return std::nullopt;
  }
  if (!pending_) {  // G40 right after G41 without a move: nothing to compensate
    out.push_back(m.b);
    side_ = 0;
    stopping_ = false;
    return std::nullopt;
  }
  if (auto e = join(*pending_, m, out)) return e;
  if (stopping_) {
    if (norm(xy(m.b.target) - xy(pending_from_)) <= kOnTol) {
      return CompError{m.b.line, m.b.col,
                       "the lead-out move is too short to switch the offset off"};
    }
    out.push_back(m.b);  // from the junction to the programmed (uncompensated) end
    pending_.reset();
    side_ = 0;
    stopping_ = false;
    return std::nullopt;
  }
  pending_ = m;
  return std::nullopt;
}

std::optional<CompError> WireOffset::join(const CompMove& a, const CompMove& b,
                                          std::vector<MotionBlock>& out) {
  const double s = static_cast<double>(side_);
  const P2 corner = xy(a.b.target);
  const P2 ta = tangent(a, corner), tb = tangent(b, corner);
  const P2 a_end = corner + (s * d_) * left(ta);
  const P2 b_start = corner + (s * d_) * left(tb);
  const double turn = cross(ta, tb);
  Vec3 to = a.b.target;
  auto finish = [&](P2 p) {
    to.x = p.x;
    to.y = p.y;
    emit(a, to, out);
  };
  if (std::fabs(turn) < 1e-9 && dot(ta, tb) > 0.0) {  // tangent: the offset paths meet
    finish(a_end);
    pending_from_ = {b_start.x, b_start.y, b.from.z};
  } else if (s * turn < 0.0 || std::fabs(turn) < 1e-9) {  // outside (or a reversal): an arc
    finish(a_end);
    MotionBlock arc = b.b;
    arc.kind = s > 0.0 ? MotionKind::kArcCw : MotionKind::kArcCcw;
    arc.centre = {corner.x, corner.y, a.b.target.z};
    arc.target = {b_start.x, b_start.y, a.b.target.z};
    arc.turns = 0;
    out.push_back(arc);
    pending_from_ = arc.target;
  } else {  // inside: where the two offset paths cross
    auto element = [&](const CompMove& m, P2 from, P2 to_p) {
      Element e;
      e.arc = is_arc(m.b);
      e.a = from;
      e.b = to_p;
      if (e.arc) {
        e.ccw = m.b.kind == MotionKind::kArcCcw;
        e.c = xy(m.b.centre);
        e.r = norm(from - e.c);
      } else {
        const P2 d = to_p - from;
        const double n = norm(d);
        e.p = from;
        e.u = n > kEps ? (1.0 / n) * d : tangent(m, from);
      }
      return e;
    };
    const Element ea = element(a, xy(pending_from_), a_end);
    const P2 tb_end = tangent(b, xy(b.b.target));
    const P2 b_end =
        stopping_ ? xy(b.b.target) + (s * d_) * left(tb) : xy(b.b.target) + (s * d_) * left(tb_end);
    const Element eb = element(b, b_start, b_end);
    const std::vector<P2> xs = intersect(ea, eb);
    bool found = false;
    P2 best{};
    for (const P2& x : xs) {
      if (!ea.holds(x) || !eb.holds(x)) continue;
      if (!found || norm(x - corner) < norm(best - corner)) best = x;
      found = true;
    }
    if (!found) {
      return CompError{b.b.line, b.b.col,
                       "the wire offset " + mm3(d_) +
                           " mm cannot be applied at this inside "
                           "corner: a move next to it is too short for the offset"};
    }
    finish(best);
    pending_from_ = {best.x, best.y, b.from.z};
  }
  for (const MotionBlock& h : held_) out.push_back(h);
  held_.clear();
  return std::nullopt;
}

}  // namespace edm::hmi::detail
