// Word rules of a block; see gcode_block.hpp and docs/gcode.md.

#include "gcode_block.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>

namespace edm::hmi::detail {

int code10(const Word& w) noexcept {
  if (!(w.value >= 0.0 && w.value < 10000.0)) return -1;
  const double scaled = w.value * 10.0;
  const double r = std::round(scaled);
  return std::fabs(scaled - r) < 1e-6 ? static_cast<int>(r) : -1;
}

std::string word_text(const Word& w) { return "'" + std::string(w.text) + "'"; }

bool is_whole(double v) noexcept { return std::fabs(v) < 1e9 && v == std::floor(v); }

namespace {

// The G and M codes this dialect knows (as code10: G02 is 20, G160 is 1600), by modal group.
struct CodeGroup {
  char letter;
  std::array<int, 4> codes;
  std::size_t count;
  const Word* Block::*slot;
  const char* name;  // how a conflict names the group
};
constexpr CodeGroup kCodeGroups[] = {
    {'G', {0, 10, 20, 30}, 4, &Block::motion_g, "motion codes (modal group 1: G00 G01 G02 G03)"},
    {'G',
     {40, 1600, 920, 921},
     4,
     &Block::nonmodal_g,
     "non-modal codes (group 0: G04 G160 G92 G92.1)"},
    {'G', {540, 550, 560, 570}, 4, &Block::frame_g, "work-frame codes (modal group 12: G54..G59)"},
    {'G', {580, 590}, 2, &Block::frame_g, "work-frame codes (modal group 12: G54..G59)"},
    {'G', {170}, 1, &Block::plane_g, "plane codes (modal group 2)"},
    {'G', {200, 210}, 2, &Block::units_g, "unit codes (modal group 6: G20 G21)"},
    {'G', {900, 910}, 2, &Block::distance_g, "distance-mode codes (modal group 3: G90 G91)"},
    {'M',
     {0, 10, 20, 300},
     4,
     &Block::stop_m,
     "stop and end codes (modal group 4: M00 M01 M02 M30)"},
    {'G', {400, 410, 420}, 3, &Block::comp_g, "wire-offset codes (modal group 7: G40 G41 G42)"},
    {'M', {980, 990}, 2, &Block::sub_m, "subprogram codes (M98 call, M99 return)"},
    {'M', {30, 50}, 2, &Block::rotation_m, "rotation codes (modal group 7: M03 M05)"},
    {'M', {80, 90}, 2, &Block::flushing_m, "flushing codes (modal group 8: M08 M09)"},
};

class Sorter {
 public:
  explicit Sorter(std::vector<GcodeError>& errors) : errors_(errors) {}

  bool set_group(const Block& b, const Word*& slot, const Word& w, const char* group) {
    if (slot != nullptr) {
      error(b, &w,
            word_text(w) + " conflicts with " + word_text(*slot) + " in the same block: both are " +
                group);
      return false;
    }
    slot = &w;
    return true;
  }

  // G and M words: the modal group's slot (a second word of the group is a conflict), else why
  // the code is refused.
  bool sort_code(Block& b, const Word& w) {
    const int code = code10(w);
    for (const CodeGroup& g : kCodeGroups) {
      const auto codes = std::span(g.codes).first(g.count);
      if (g.letter == w.letter && std::find(codes.begin(), codes.end(), code) != codes.end()) {
        return set_group(b, b.*g.slot, w, g.name);
      }
    }
    if (w.letter == 'M') {
      error(b, &w, "unknown M code " + word_text(w));
    } else if (code == 180 || code == 190) {
      error(b, &w, word_text(w) + " is not supported: arcs are in the XY plane only (G17)");
    } else if (code == 591 || code == 592 || code == 593) {
      error(b, &w, word_text(w) + " is not supported: the work frames are G54..G59");
    } else if (code == 530) {
      error(b, &w,
            word_text(w) +
                " (a move in machine coordinates) is not supported: select a work "
                "frame G54..G59 whose offset is zero instead");
    } else if (code == 922 || code == 923) {
      error(b, &w,
            word_text(w) + " is not supported: G92 offsets are not retained; G92.1 clears them");
    } else {
      error(b, &w, "unknown G code " + word_text(w));
    }
    return false;
  }

  bool sort_words(const std::vector<Word>& words, Block& b) {
    bool ok = true;
    b.first = &words.front();
    for (std::size_t i = 0; i < words.size(); ++i) {
      const Word& w = words[i];
      switch (w.letter) {
        case 'N':
          if (i != 0) {
            error(b, &w, "'N' (block number) must be the first word of the block");
            ok = false;
          } else if (w.value < 0.0 || !is_whole(w.value)) {
            error(b, &w, "block number " + word_text(w) + " must be a whole number >= 0");
            ok = false;
          }
          break;
        case 'G':
        case 'M': ok = sort_code(b, w) && ok; break;
        case 'X':
        case 'Y':
        case 'Z':
        case 'I':
        case 'J':
        case 'F':
        case 'E':
        case 'P':
        case 'D':
        case 'L':
        case 'O':
        case 'R': {
          const Word*& slot = b.value[static_cast<std::size_t>(w.letter - 'A')];
          if (slot != nullptr) {
            error(b, &w,
                  std::string("'") + w.letter + "' given twice in one block (first at column " +
                      std::to_string(slot->col) + ")");
            ok = false;
          } else {
            slot = &w;
          }
          break;
        }
        case 'K':
          error(b, &w,
                "unknown word " + word_text(w) +
                    ": arcs are in the XY plane only (G17), their centre is given by I and J");
          ok = false;
          break;
        default:
          error(b, &w,
                "unknown word " + word_text(w) + ": this dialect has no '" + w.letter + "' words");
          ok = false;
          break;
      }
    }
    if (!ok) return false;
    if (b.nonmodal_g == nullptr) return ok;
    const int nonmodal = code10(*b.nonmodal_g);
    // G04, G160 and G92.1 run on their own: no motion code, axis or centre words beside them;
    // G92's axis words are its own (the coordinates the current point gets).
    const bool g92 = nonmodal == 920;
    for (const Word* w : {b.motion_g, g92 ? nullptr : b['X'], g92 ? nullptr : b['Y'],
                          g92 ? nullptr : b['Z'], b['I'], b['J']}) {
      if (w != nullptr) {
        error(b, w, word_text(*w) + " cannot share a block with " + word_text(*b.nonmodal_g));
        ok = false;
      }
    }
    if (g92 && b.first_axis() == nullptr) {
      error(b, b.nonmodal_g,
            "G92 needs X, Y and/or Z (the coordinates the current point is to have)");
      ok = false;
    }
    // Which comes first, the new frame or the offset change, is a guess either way: refuse it.
    if ((g92 || nonmodal == 921) && b.frame_g != nullptr) {
      const bool frame_first = b.frame_g->col < b.nonmodal_g->col;
      const Word* second = frame_first ? b.nonmodal_g : b.frame_g;
      const Word* first = frame_first ? b.frame_g : b.nonmodal_g;
      error(b, second,
            word_text(*second) + " conflicts with " + word_text(*first) +
                " in the same block: select the work frame and set or clear the G92 offset in "
                "separate blocks");
      ok = false;
    }
    return ok;
  }

 private:
  void error(const Block& b, const Word* at, std::string message) {
    errors_.push_back({b.line, at != nullptr ? at->col : 1, std::move(message)});
  }

  std::vector<GcodeError>& errors_;
};

}  // namespace

bool sort_block(const std::vector<Word>& words, int line, Block& b,
                std::vector<GcodeError>& errors) {
  b.line = line;
  return Sorter(errors).sort_words(words, b);
}

}  // namespace edm::hmi::detail
