// G-code interpreter: modal state, word checks, motion blocks. The dialect is documented in
// docs/gcode.md; the execution order inside a block follows RS274/NGC (F, E, M03/M05, M08/M09,
// G04/G160, G17/G21/G90/G91, motion, M02/M30).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/program_check.hpp"
#include "edm/machining/wear_precomp.hpp"
#include "gcode_block.hpp"
#include "gcode_lexer.hpp"

namespace edm::hmi {

using machining::Condition;
using machining::MachineTables;
using machining::MotionBlock;
using machining::MotionKind;
using machining::Polarity;
using machining::Vec3;

std::vector<std::string> GcodeResult::messages() const {
  std::vector<std::string> out;
  out.reserve(errors.size());
  for (const GcodeError& e : errors) {
    out.push_back(file + ":" + std::to_string(e.line) + ":" + std::to_string(e.col) + ": " +
                  e.message);
  }
  return out;
}

namespace {

using detail::Block;
using detail::code10;
using detail::is_whole;
using detail::Word;
using detail::word_text;

constexpr double kEps = 1e-9;            // mm: "no motion" on an axis
constexpr double kFullCircleEps = 1e-6;  // mm: an arc ending this close to its start is full
constexpr double kZeroRadius = 1e-6;     // mm

enum class Motion : std::uint8_t { kNone, kRapid, kLinear, kArcCw, kArcCcw };

std::string mm(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

class Interpreter {
 public:
  Interpreter(std::string_view text, std::string_view file, const MachineTables& tables,
              const GcodeOptions& options)
      : text_(text), tables_(tables), opt_(options) {
    result_.file = std::string(file);
    pos_ = opt_.start_mm;
    const double f = opt_.default_feed_mm_min;
    feed_mm_min_ = f > 0.0 && std::isfinite(f) ? f : 0.0;
  }

  GcodeResult run() {
    int line_no = 0;
    std::size_t begin = 0;
    while (begin < text_.size() && !stop_) {
      std::size_t end = text_.find('\n', begin);
      if (end == std::string_view::npos) end = text_.size();
      ++line_no;
      process_line(text_.substr(begin, end - begin), line_no);
      begin = end + 1;
    }
    if (!stop_ && !ended_) {
      error(std::max(line_no, 1), 1, "program has no end: finish it with M02 or M30");
    }
    if (!stop_) check_blocks();
    std::stable_sort(result_.errors.begin(), result_.errors.end(),
                     [](const GcodeError& a, const GcodeError& b) {
                       return a.line != b.line ? a.line < b.line : a.col < b.col;
                     });
    if (too_many_) {
      result_.errors.push_back(
          {line_no, 1, "too many errors (" + std::to_string(opt_.max_errors) + "), stopping"});
    }
    if (!result_.errors.empty()) result_.blocks.clear();
    return std::move(result_);
  }

 private:
  void error(int line, int col, std::string message) {
    if (result_.errors.size() >= opt_.max_errors) {
      too_many_ = stop_ = true;
      return;
    }
    result_.errors.push_back({line, col, std::move(message)});
  }
  void error(const Block& b, const Word* at, std::string message) {
    error(b.line, at != nullptr ? at->col : 1, std::move(message));
  }

  void process_line(std::string_view line, int line_no) {
    if (closed_) return;  // after the closing '%' nothing is read
    if (line.size() > opt_.max_line_length) {
      error(line_no, static_cast<int>(opt_.max_line_length) + 1,
            "line longer than " + std::to_string(opt_.max_line_length) + " characters");
      return;
    }
    const std::size_t errors_before = result_.errors.size();
    detail::LexedLine lexed = detail::lex_line(line, line_no, result_.errors);
    if (result_.errors.size() > opt_.max_errors) {
      result_.errors.resize(opt_.max_errors);
      too_many_ = stop_ = true;
      return;
    }
    if (lexed.percent && lexed.words.empty() && result_.errors.size() == errors_before) {
      if (!seen_block_ && !opened_) {
        opened_ = true;  // the opening delimiter
      } else {
        closed_ = true;  // the closing one: the rest of the file is ignored
      }
      return;
    }
    if (lexed.words.empty()) return;
    seen_block_ = true;
    if (ended_) {
      if (!reported_after_end_) {
        error(line_no, lexed.words.front().col,
              "nothing may follow the program end (" + end_word_ + " on line " +
                  std::to_string(end_line_) + ")");
        reported_after_end_ = true;
      }
      return;
    }
    if (result_.errors.size() != errors_before) return;  // a malformed line is not executed
    Block b;
    const bool sorted = detail::sort_block(lexed.words, line_no, b, result_.errors);
    if (result_.errors.size() > opt_.max_errors) {
      result_.errors.resize(opt_.max_errors);
      too_many_ = stop_ = true;
      return;
    }
    if (sorted) execute(b);
  }

  // --- Execution. ----------------------------------------------------------------------------

  [[nodiscard]] bool is_code(const Word* w, int c10) const noexcept {
    return w != nullptr && code10(*w) == c10;
  }

  MotionBlock make(MotionKind kind, const Block& b, const Word* at) const {
    MotionBlock mb{};
    mb.kind = kind;
    mb.line = b.line;
    mb.col = at != nullptr ? at->col : (b.first != nullptr ? b.first->col : 1);
    mb.target = pos_;
    mb.condition = armed_;
    return mb;
  }

  /// The soft limits (end points, arc and orbit extents, drilling travel) are checked by
  /// machining::check_program, the check the runtime runs at program.commit, so the HMI and the
  /// runtime refuse the same programs with the same words. An end point beyond a limit is
  /// reported at its axis word, anything else at the word that made the block. Issues other than
  /// soft limits mean the two disagree; they are reported only for a program that is otherwise
  /// clean (after a refused line the blocks no longer follow the modelled position).
  void check_blocks() {
    machining::ProgramCheckOptions o;
    o.arc_tolerance_mm = opt_.arc_tolerance_mm;
    const bool clean = result_.errors.empty();
    for (const machining::ProgramIssue& is :
         machining::check_program(result_.blocks, tables_, opt_.start_mm, o)) {
      if (!is.soft_limit && !clean) continue;
      int col = is.col;
      if (is.axis != 0 && static_cast<std::size_t>(is.line) < axis_cols_.size()) {
        const int axis_col = axis_cols_[static_cast<std::size_t>(is.line)][axis_index(is.axis)];
        if (axis_col > 0) col = axis_col;
      }
      error(is.line, col, is.message);
      if (stop_) return;
    }
  }

  static std::size_t axis_index(char axis) noexcept {
    return static_cast<std::size_t>(axis == 'X' ? 0 : axis == 'Y' ? 1 : 2);
  }

  bool need_feed(const Block& b, const Word* at, const char* what) {
    if (feed_mm_min_ > 0.0) return true;
    if (!reported_no_feed_) {
      error(
          b, at,
          std::string(what) + " needs a feed rate: program F (mm/min) before the first feed move");
      reported_no_feed_ = true;
    }
    return false;
  }

  void execute(const Block& b) {
    // Phase 1: every check that depends only on the words and the state; no effects yet, so a
    // refused block changes nothing.
    bool ok = true;
    const Word* f = b['F'];
    if (f != nullptr && !(f->value > 0.0)) {
      error(b, f, "feed rate " + word_text(*f) + " must be > 0 (mm/min)");
      ok = false;
    }
    int armed_after = armed_;
    const Word* e = b['E'];
    if (e != nullptr) {
      if (e->value < 0.0 || !is_whole(e->value)) {
        error(b, e, "condition " + word_text(*e) + " must be a whole number >= 0 (E0 disarms)");
        ok = false;
      } else {
        const int n = static_cast<int>(e->value);
        if (n >= 1 && tables_.condition(n) == nullptr) {
          error(b, e, "unknown condition " + word_text(*e) + " (" + known_conditions() + ")");
          ok = false;
        }
        armed_after = n;
      }
    }
    const bool incremental = b.distance_g != nullptr ? is_code(b.distance_g, 910) : incremental_;
    const Motion mode = b.motion_g != nullptr ? motion_of(*b.motion_g) : mode_;
    const bool arc = mode == Motion::kArcCw || mode == Motion::kArcCcw;
    const bool has_axis = b.first_axis() != nullptr;
    const bool has_ij = b['I'] != nullptr || b['J'] != nullptr;
    const bool dwell = is_code(b.nonmodal_g, 40);
    const bool orbit = is_code(b.nonmodal_g, 1600);
    const bool arc_move = arc && (has_axis || has_ij);

    if (has_ij && !arc) {
      const Word* w = b['I'] != nullptr ? b['I'] : b['J'];
      error(b, w, word_text(*w) + " is only used by G02/G03 arcs (centre offset)");
      ok = false;
    }
    if (arc && !has_ij && (b.motion_g != nullptr || has_axis)) {
      const Word* at = b.motion_g != nullptr ? b.motion_g : b.first_axis();
      error(b, at,
            std::string(mode == Motion::kArcCw ? "G02" : "G03") +
                " needs I and/or J (the centre, relative to the start point)");
      ok = false;
    }
    if (has_axis && mode == Motion::kNone) {
      error(b, b.first_axis(),
            word_text(*b.first_axis()) +
                " without a motion mode: program G00, G01, G02 or G03 first");
      ok = false;
    }
    if (const Word* r = b['R']; r != nullptr && !orbit) {
      error(b, r,
            word_text(*r) +
                " is only used by the G160 orbit cycle (arcs take I and J, not a radius)");
      ok = false;
    }
    const Word* p = b['P'];
    if (p != nullptr && !dwell && !(arc_move && has_ij)) {
      error(b, p, word_text(*p) + " is only used by G04 (dwell) and G02/G03 (extra turns)");
      ok = false;
    }
    if (dwell) {
      if (p == nullptr) {
        error(b, b.nonmodal_g, "G04 needs P (the dwell time in seconds)");
        ok = false;
      } else if (p->value < 0.0) {
        error(b, p, "dwell " + word_text(*p) + " must be >= 0 seconds");
        ok = false;
      }
    }
    if (arc_move && p != nullptr &&
        (p->value < 0.0 || !is_whole(p->value) || p->value > opt_.max_arc_turns)) {
      error(b, p,
            "extra turns " + word_text(*p) + " must be a whole number 0.." +
                std::to_string(opt_.max_arc_turns));
      ok = false;
    }
    if (orbit && !check_orbit_words(b, armed_after)) ok = false;
    if (!ok) return;

    // Phase 2: effects, in RS274/NGC order.
    if (f != nullptr) feed_mm_min_ = f->value;
    if (e != nullptr) {
      armed_ = armed_after;
      MotionBlock mb = make(MotionKind::kCondition, b, e);
      result_.blocks.push_back(mb);
    }
    if (b.rotation_m != nullptr) {
      MotionBlock mb = make(MotionKind::kRotation, b, b.rotation_m);
      mb.on = is_code(b.rotation_m, 30);
      result_.blocks.push_back(mb);
    }
    if (b.flushing_m != nullptr) {
      MotionBlock mb = make(MotionKind::kFlushing, b, b.flushing_m);
      mb.on = is_code(b.flushing_m, 80);
      result_.blocks.push_back(mb);
    }
    if (dwell) {
      MotionBlock mb = make(MotionKind::kDwell, b, b.nonmodal_g);
      mb.dwell_s = p->value;
      result_.blocks.push_back(mb);
    }
    incremental_ = incremental;
    if (b.motion_g != nullptr) mode_ = mode;
    if (orbit) do_orbit(b);
    if (has_axis || arc_move) do_motion(b);
    if (b.stop_m != nullptr) {
      result_.blocks.push_back(make(MotionKind::kEnd, b, b.stop_m));
      ended_ = true;
      end_line_ = b.line;
      end_word_ = std::string(b.stop_m->text);
    }
  }

  static Motion motion_of(const Word& g) noexcept {
    switch (code10(g)) {
      case 0:
        return Motion::kRapid;
      case 10:
        return Motion::kLinear;
      case 20:
        return Motion::kArcCw;
      default:
        return Motion::kArcCcw;
    }
  }

  [[nodiscard]] std::string known_conditions() const {
    if (tables_.conditions.empty()) return "this machine has no conditions";
    std::string s = "this machine has";
    for (const Condition& c : tables_.conditions) s += " E" + std::to_string(c.e);
    return s;
  }

  bool check_orbit_words(const Block& b, int armed_after) {
    const Word* r = b['R'];
    if (r == nullptr) {
      error(b, b.nonmodal_g, "G160 needs R (the final hole radius, mm)");
      return false;
    }
    if (!(r->value > 0.0)) {
      error(b, r, "final radius " + word_text(*r) + " must be > 0 mm");
      return false;
    }
    if (armed_after < 1) {
      error(b, b.nonmodal_g,
            "G160 needs an armed condition: select a positive-polarity finishing condition "
            "with E<n> first");
      return false;
    }
    const Condition* c = tables_.condition(armed_after);
    if (c != nullptr && c->polarity != Polarity::kPositive) {
      error(b, b.nonmodal_g,
            "G160 orbit finishing needs a positive-polarity condition; E" +
                std::to_string(armed_after) + (c->name.empty() ? "" : " '" + c->name + "'") +
                " is negative");
      return false;
    }
    return true;
  }

  void do_orbit(const Block& b) {
    const double r = b['R']->value;
    MotionBlock mb = make(MotionKind::kOrbitFinish, b, b.nonmodal_g);
    mb.centre = pos_;
    mb.final_radius_mm = r;
    if (need_feed(b, b.nonmodal_g, "G160")) mb.feed_mm_s = feed_mm_min_ / 60.0;
    result_.blocks.push_back(mb);
  }

  void do_motion(const Block& b) {
    const bool inc = incremental_;
    auto coord = [&](char axis, double current) {
      const Word* w = b[axis];
      if (w == nullptr) return current;
      return inc ? current + w->value : w->value;
    };
    const Vec3 start = pos_;
    const Vec3 target{coord('X', start.x), coord('Y', start.y), coord('Z', start.z)};
    const Word* at = b.motion_g != nullptr ? b.motion_g : b.first_axis();
    if (at == nullptr) at = b['I'] != nullptr ? b['I'] : b['J'];
    remember_axis_words(b);
    switch (mode_) {
      case Motion::kRapid: {
        pos_ = target;
        result_.blocks.push_back(make(MotionKind::kRapid, b, at));
        break;
      }
      case Motion::kLinear:
        do_linear(b, at, start, target);
        break;
      case Motion::kArcCw:
      case Motion::kArcCcw:
        do_arc(b, at, start, target);
        break;
      case Motion::kNone:
        break;  // refused in phase 1
    }
  }

  void do_linear(const Block& b, const Word* at, const Vec3& start, const Vec3& target) {
    pos_ = target;
    const bool drill = armed_ >= 1 && target.z < start.z - kEps;
    MotionBlock mb = make(drill ? MotionKind::kDrill : MotionKind::kLinear, b, at);
    if (need_feed(b, at, "G01")) mb.feed_mm_s = feed_mm_min_ / 60.0;
    if (!drill) {
      result_.blocks.push_back(mb);
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
    const Condition* c = tables_.condition(armed_);
    const double lz = start.z - target.z;
    // Eq. (9)-(11): wear is planned for the depth eroded, below the work surface (Z0).
    const double lz_cut = std::max(0.0, std::min(start.z, 0.0) - target.z);
    const machining::WearPrecomp wp = machining::wear_precompensate(
        lz_cut, c != nullptr ? c->wear_ratio : 0.0, c != nullptr ? c->area_ratio : 1.0);
    mb.z_travel_mm = lz + wp.delta_mm;
    result_.blocks.push_back(mb);
    pos_ = start;  // the runtime retracts out of the hole and returns to the block's start
    result_.drill_depth_mm += lz_cut;
    result_.electrode_wear_mm += wp.delta_mm;
    ++result_.drill_blocks;
  }

  void do_arc(const Block& b, const Word* at, const Vec3& start, Vec3 target) {
    pos_ = target;
    const char* name = mode_ == Motion::kArcCw ? "G02" : "G03";
    if (std::fabs(target.z - start.z) > kEps) {
      error(
          b, b['Z'],
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
    MotionBlock mb =
        make(mode_ == Motion::kArcCw ? MotionKind::kArcCw : MotionKind::kArcCcw, b, at);
    mb.centre = centre;
    mb.turns = b['P'] != nullptr ? static_cast<std::int32_t>(b['P']->value) : 0;
    if (need_feed(b, at, name)) mb.feed_mm_s = feed_mm_min_ / 60.0;
    result_.blocks.push_back(mb);
  }

  /// Where this line's X, Y and Z words are (columns, 0 = absent), for soft-limit messages.
  void remember_axis_words(const Block& b) {
    const auto line = static_cast<std::size_t>(b.line);
    if (axis_cols_.size() <= line) axis_cols_.resize(std::max(line + 1, 2 * axis_cols_.size()));
    for (char axis : {'X', 'Y', 'Z'}) {
      axis_cols_[line][axis_index(axis)] = b[axis] != nullptr ? b[axis]->col : 0;
    }
  }

  std::string_view text_;
  const MachineTables& tables_;
  const GcodeOptions& opt_;
  GcodeResult result_;
  std::vector<std::array<int, 3>> axis_cols_;  // by line: columns of X, Y, Z words

  Vec3 pos_{};
  Motion mode_{Motion::kNone};
  bool incremental_{false};
  double feed_mm_min_{0.0};
  int armed_{0};

  bool opened_{false};
  bool closed_{false};
  bool seen_block_{false};
  bool ended_{false};
  int end_line_{0};
  std::string end_word_;
  bool reported_after_end_{false};
  bool reported_no_feed_{false};
  bool stop_{false};
  bool too_many_{false};
};

}  // namespace

GcodeResult interpret_gcode(std::string_view text, std::string_view file,
                            const MachineTables& tables, const GcodeOptions& options) {
  return Interpreter(text, file, tables, options).run();
}

}  // namespace edm::hmi
