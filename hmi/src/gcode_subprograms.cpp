// G-code interpreter: subprograms (docs/gcode.md "Subprograms"). `O<n>` alone on a line opens a
// definition, `M99` alone on a line closes it; the lines between are its body, run by
// `M98 P<n> [L<k>]` k times (a skim pass over the same contour). Definitions may stand anywhere,
// after M30 too, and are skipped where they stand. Calls nest up to kMaxDepth deep; the lines run
// through calls are bounded (100 000), so no program makes the interpreter loop without end or
// fill memory with blocks.

#include <string>

#include "gcode_interpreter.hpp"
#include "gcode_lexer.hpp"

namespace edm::hmi::detail {
namespace {
constexpr int kMaxDepth = 8;
constexpr std::size_t kMaxCalledLines = 100'000;
constexpr double kMaxRepeats = 1000.0;
}  // namespace

std::string_view Interpreter::line_text(int line_no) const {
  return lines_[static_cast<std::size_t>(line_no - 1)];
}

void Interpreter::scan_subprograms() {
  std::size_t begin = 0;
  while (begin < text_.size()) {
    std::size_t end = text_.find('\n', begin);
    if (end == std::string_view::npos) end = text_.size();
    lines_.push_back(text_.substr(begin, end - begin));
    begin = end + 1;
  }
  in_definition_.assign(lines_.size(), 0);
  const SubprogramDef none{};
  SubprogramDef open = none;
  long open_n = 0;
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    if (lines_[i].size() > opt_.max_line_length) continue;  // the flow reports it
    std::vector<GcodeError> scratch;  // the flow reports the line's own errors
    const LexedLine lexed = lex_line(lines_[i], static_cast<int>(i + 1), scratch);
    if (!scratch.empty() || lexed.words.empty()) {
      if (open.o_line != 0) in_definition_[i] = 1;
      continue;
    }
    const Word& w = lexed.words.front();
    const bool o_word = w.letter == 'O';
    const bool m99 = w.letter == 'M' && code10(w) == 990;
    const int line = static_cast<int>(i + 1);
    if (o_word) {
      if (open.o_line != 0) {
        error(line, w.col,
              "subprogram definitions do not nest: O" + std::to_string(open_n) + " (line " +
                  std::to_string(open.o_line) + ") has no M99 yet");
        continue;
      }
      if (lexed.words.size() != 1) {
        error(line, lexed.words[1].col, "O<n> opens a subprogram and stands alone on its line");
      }
      if (!(w.value >= 1.0) || !is_whole(w.value)) {
        error(line, w.col, "subprogram number " + word_text(w) + " must be a whole number >= 1");
      }
      open = {line, line + 1, line};
      open_n = static_cast<long>(w.value);
      in_definition_[i] = 1;
    } else if (m99 && open.o_line != 0) {
      if (lexed.words.size() != 1) {
        error(line, lexed.words[1].col, "M99 closes a subprogram and stands alone on its line");
      }
      open.last = line - 1;
      in_definition_[i] = 1;
      if (!subprograms_.emplace(open_n, open).second) {
        error(open.o_line, 1,
              "subprogram O" + std::to_string(open_n) + " is defined twice (first at line " +
                  std::to_string(subprograms_[open_n].o_line) + ")");
      }
      open = none;
    } else if (open.o_line != 0) {
      in_definition_[i] = 1;
    }
  }
  if (open.o_line != 0) {
    error(open.o_line, 1,
          "subprogram O" + std::to_string(open_n) + " has no M99 (the end of its definition)");
  }
}

void Interpreter::call_subprogram(const Block& b) {
  const Word* p = b['P'];
  const Word* l = b['L'];
  if (p == nullptr || !is_whole(p->value)) {
    error(b, p != nullptr ? p : b.sub_m, "M98 needs P<n>, the number of the subprogram O<n>");
    return;
  }
  const auto it = subprograms_.find(static_cast<long>(p->value));
  if (it == subprograms_.end()) {
    error(b, p,
          "M98 " + word_text(*p) + ": this program has no subprogram O" +
              std::to_string(static_cast<long>(p->value)));
    return;
  }
  double repeats = 1.0;
  if (l != nullptr) {
    if (!is_whole(l->value) || l->value < 1.0 || l->value > kMaxRepeats) {
      error(b, l, "repeat count " + word_text(*l) + " must be a whole number 1..1000");
      return;
    }
    repeats = l->value;
  }
  if (call_depth_ >= kMaxDepth) {
    error(b, b.sub_m,
          "subprogram calls nest deeper than " + std::to_string(kMaxDepth) +
              " (a subprogram that calls itself?)");
    return;
  }
  ++call_depth_;
  const SubprogramDef def = it->second;
  for (int k = 0; k < static_cast<int>(repeats) && !stop_; ++k) {
    for (int line = def.first; line <= def.last && !stop_; ++line) {
      if (++lines_called_ > kMaxCalledLines) {
        error(b, b.sub_m, "subprogram calls run more than 100000 lines: the program is refused");
        stop_ = true;
        break;
      }
      process_line(line_text(line), line);
    }
  }
  --call_depth_;
}

}  // namespace edm::hmi::detail
