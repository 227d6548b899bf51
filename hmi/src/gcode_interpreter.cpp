// G-code interpreter: the line loop, word checks and modal state. The dialect is documented in
// docs/gcode.md; the execution order inside a block follows RS274/NGC (F, E, M03/M05, M08/M09,
// G04, G17/G21/G90/G91, G54..G59, G92/G92.1, G160 or the motion, M02/M30). The motion itself is
// in gcode_motion.cpp.

#include "gcode_interpreter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/program_check.hpp"
#include "gcode_block.hpp"
#include "gcode_lexer.hpp"

namespace edm::hmi {

using machining::Condition;
using machining::MachineTables;
using machining::MotionBlock;
using machining::MotionKind;
using machining::Polarity;

std::vector<std::string> GcodeResult::messages() const {
  std::vector<std::string> out;
  out.reserve(errors.size());
  for (const GcodeError& e : errors) {
    out.push_back(file + ":" + std::to_string(e.line) + ":" + std::to_string(e.col) + ": " +
                  e.message);
  }
  return out;
}

namespace detail {

std::string mm(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

namespace {

Motion motion_of(const Word& g) noexcept {
  switch (code10(g)) {
    case 0: return Motion::kRapid;
    case 10: return Motion::kLinear;
    case 20: return Motion::kArcCw;
    default: return Motion::kArcCcw;
  }
}

}  // namespace

Interpreter::Interpreter(std::string_view text, std::string_view file, const MachineTables& tables,
                         const GcodeOptions& options)
    : text_(text), tables_(tables), opt_(options) {
  result_.file = std::string(file);
  result_.start_mm = opt_.start_mm;
  result_.electrode_mm = opt_.offsets.electrode_mm;
  pos_ = opt_.start_mm;
  const double f = opt_.default_feed_mm_min;
  feed_mm_min_ = f > 0.0 && std::isfinite(f) ? f : 0.0;
}

GcodeResult Interpreter::run() {
  scan_subprograms();
  int line_no = 0;
  for (std::size_t i = 0; i < lines_.size() && !stop_; ++i) {
    line_no = static_cast<int>(i + 1);
    if (in_definition_[i] == 0) process_line(lines_[i], line_no);
  }
  if (!stop_ && !ended_) {
    if (opt_.implicit_end) {
      MotionBlock mb = make(MotionKind::kEnd, Block{}, nullptr);
      mb.line = std::max(last_line_, 1);
      mb.col = 0;
      push(mb);
      ended_ = true;
    } else {
      error(std::max(line_no, 1), 1, "program has no end: finish it with M02 or M30");
    }
  }
  if (!stop_) check_blocks();
  std::stable_sort(result_.errors.begin(), result_.errors.end(),
                   [](const GcodeError& a, const GcodeError& b) {
                     return a.line != b.line ? a.line < b.line : a.col < b.col;
                   });
  if (too_many_) {  // after the last one reported (a subprogram's may lie past where it stopped)
    const int at = std::max(line_no, result_.errors.empty() ? 1 : result_.errors.back().line);
    result_.errors.push_back(
        {at, 1, "too many errors (" + std::to_string(opt_.max_errors) + "), stopping"});
  }
  if (!result_.errors.empty()) {
    result_.blocks.clear();
    result_.frames.clear();
  }
  return std::move(result_);
}

void Interpreter::error(int line, int col, std::string message) {
  if (result_.errors.size() >= opt_.max_errors) {
    too_many_ = stop_ = true;
    return;
  }
  result_.errors.push_back({line, col, std::move(message)});
}

void Interpreter::error(const Block& b, const Word* at, std::string message) {
  error(b.line, at != nullptr ? at->col : 1, std::move(message));
}

void Interpreter::process_line(std::string_view line, int line_no) {
  if (closed_) return;  // after the closing '%' nothing is read
  if (line.size() > opt_.max_line_length) {
    error(line_no, static_cast<int>(opt_.max_line_length) + 1,
          "line longer than " + std::to_string(opt_.max_line_length) + " characters");
    return;
  }
  const std::size_t errors_before = result_.errors.size();
  LexedLine lexed = lex_line(line, line_no, result_.errors);
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
  last_line_ = line_no;
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
  apply_units(lexed.words);
  Block b;
  const bool sorted = sort_block(lexed.words, line_no, b, result_.errors);
  if (result_.errors.size() > opt_.max_errors) {
    result_.errors.resize(opt_.max_errors);
    too_many_ = stop_ = true;
    return;
  }
  if (sorted) execute(b);
}

void Interpreter::apply_units(std::vector<Word>& words) {
  for (const Word& w : words) {
    if (w.letter == 'G' && code10(w) == 200) inch_ = true;
    if (w.letter == 'G' && code10(w) == 210) inch_ = false;
  }
  if (!inch_) return;
  constexpr double kMmPerInch = 25.4;  // exact, by definition
  for (Word& w : words) {
    switch (w.letter) {
      case 'X':
      case 'Y':
      case 'Z':
      case 'I':
      case 'J':
      case 'R':
      case 'F': w.value *= kMmPerInch; break;
      default: break;
    }
  }
}

/// The soft limits (end points, arc and orbit extents, drilling travel) are checked by
/// machining::check_program, the check the runtime runs at program.commit, so the HMI and the
/// runtime refuse the same programs with the same words. The blocks are in machine coordinates,
/// so are the limits. An end point beyond a limit is reported at its axis word, anything else at
/// the word that made the block. Issues other than soft limits mean the two disagree; they are
/// reported only for a program that is otherwise clean (after a refused line the blocks no longer
/// follow the modelled position).
void Interpreter::check_blocks() {
  machining::ProgramCheckOptions o;
  o.arc_tolerance_mm = opt_.arc_tolerance_mm;
  o.electrode_mm = opt_.offsets.electrode_mm;
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

bool Interpreter::need_feed(const Block& b, const Word* at, const char* what) {
  if (feed_mm_min_ > 0.0) return true;
  if (!reported_no_feed_) {
    error(b, at,
          std::string(what) + " needs a feed rate: program F (mm/min) before the first feed move");
    reported_no_feed_ = true;
  }
  return false;
}

void Interpreter::execute(const Block& b) {
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
  const bool g92 = is_code(b.nonmodal_g, 920);
  const bool has_axis = !g92 && b.first_axis() != nullptr;  // G92's axis words are its own
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
    error(
        b, b.first_axis(),
        word_text(*b.first_axis()) + " without a motion mode: program G00, G01, G02 or G03 first");
    ok = false;
  }
  if (const Word* r = b['R']; r != nullptr && !orbit) {
    error(
        b, r,
        word_text(*r) + " is only used by the G160 orbit cycle (arcs take I and J, not a radius)");
    ok = false;
  }
  const Word* p = b['P'];
  if (p != nullptr && !dwell && !(arc_move && has_ij) && !is_code(b.sub_m, 980)) {
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
  const bool call = is_code(b.sub_m, 980);
  if (is_code(b.sub_m, 990)) {
    error(b, b.sub_m, "M99 outside a subprogram (O<n> ... M99)");
    ok = false;
  }
  for (char letter : {'L', 'O', 'D'}) {
    const Word* w = b[letter];
    if (w == nullptr) continue;
    if ((letter == 'L' && !call) || letter == 'O' ||
        (letter == 'D' && !(is_code(b.comp_g, 410) || is_code(b.comp_g, 420)))) {
      error(b, w,
            word_text(*w) + (letter == 'L'   ? " is only used by M98 (the repeat count)"
                             : letter == 'O' ? ": O<n> opens a subprogram alone on its line"
                                             : " is only used by G41/G42 (the wire offset, mm)"));
      ok = false;
    }
  }
  if (b.comp_g != nullptr && tables_.kind != machining::MachineKind::kWire) {
    error(b, b.comp_g,
          word_text(*b.comp_g) + " (wire offset) is for wire machines (machine.kind: wire)");
    ok = false;
  }
  if (!ok) return;

  // Phase 2: effects, in RS274/NGC order.
  if (f != nullptr) feed_mm_min_ = f->value;
  if (e != nullptr) {
    armed_ = armed_after;
    push(make(MotionKind::kCondition, b, e));
  }
  if (b.rotation_m != nullptr) {
    MotionBlock mb = make(MotionKind::kRotation, b, b.rotation_m);
    mb.on = is_code(b.rotation_m, 30);
    push(mb);
  }
  if (b.flushing_m != nullptr) {
    MotionBlock mb = make(MotionKind::kFlushing, b, b.flushing_m);
    mb.on = is_code(b.flushing_m, 80);
    push(mb);
  }
  if (dwell) {
    MotionBlock mb = make(MotionKind::kDwell, b, b.nonmodal_g);
    mb.dwell_s = p->value;
    push(mb);
  }
  incremental_ = incremental;
  if (b.frame_g != nullptr) frame_ = (code10(*b.frame_g) - 540) / 10;
  if (g92) set_g92(b);
  if (is_code(b.nonmodal_g, 921)) {
    g92_ = {};
    g92_active_ = false;
  }
  if (b.motion_g != nullptr) mode_ = mode;
  if (b.comp_g != nullptr && !set_wire_offset(b)) return;
  if (orbit) do_orbit(b);
  if (has_axis || arc_move) do_motion(b);
  if (call) call_subprogram(b);
  if (b.stop_m != nullptr && code10(*b.stop_m) <= 10) {  // M00, M01: the job holds there
    MotionBlock mb = make(MotionKind::kProgramStop, b, b.stop_m);
    mb.on = is_code(b.stop_m, 10);
    push(mb);
  } else if (b.stop_m != nullptr) {
    if (auto open = comp_.at_end(b.line, b.stop_m->col)) {
      error(open->line, open->col, open->message);
    }
    push(make(MotionKind::kEnd, b, b.stop_m));
    ended_ = true;
    end_line_ = b.line;
    end_word_ = std::string(b.stop_m->text);
  }
}

std::string Interpreter::known_conditions() const {
  if (tables_.conditions.empty()) return "this machine has no conditions";
  std::string s = "this machine has";
  for (const Condition& c : tables_.conditions) s += " E" + std::to_string(c.e);
  return s;
}

bool Interpreter::set_wire_offset(const Block& b) {
  const int g = code10(*b.comp_g);
  if (g == 400) {
    if (comp_.engaged()) comp_.stop();
    return true;
  }
  if (comp_.engaged()) {
    error(b, b.comp_g,
          word_text(*b.comp_g) + " while the wire offset is on: switch it off with G40 first");
    return false;
  }
  double d = 0.0;
  if (const Word* dw = b['D']; dw != nullptr) {
    if (!(dw->value > 0.0 && dw->value <= 10.0)) {
      error(b, dw, "wire offset " + word_text(*dw) + " must be > 0 and <= 10 mm");
      return false;
    }
    d = dw->value;
  } else {
    const Condition* c = armed_ >= 1 ? tables_.condition(armed_) : nullptr;
    if (c == nullptr || !(c->offset_mm > 0.0)) {
      error(b, b.comp_g,
            word_text(*b.comp_g) + " needs an offset: a D word (mm) or an armed condition " +
                "whose offset_mm is > 0" +
                (c != nullptr ? " (E" + std::to_string(c->e) + " has none)" : std::string()));
      return false;
    }
    d = c->offset_mm;
  }
  comp_.start(g == 410 ? 1 : -1, d);
  return true;
}

bool Interpreter::check_orbit_words(const Block& b, int armed_after) {
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

}  // namespace detail

GcodeResult interpret_gcode(std::string_view text, std::string_view file,
                            const MachineTables& tables, const GcodeOptions& options) {
  return detail::Interpreter(text, file, tables, options).run();
}

}  // namespace edm::hmi
