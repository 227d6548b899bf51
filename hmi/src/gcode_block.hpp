#pragma once
// Private to the interpreter: one line's words sorted into a block — codes into their modal
// groups, value words by letter — with the RS274/NGC word rules checked (unknown letters and
// codes, one word per modal group, no letter twice, N first, G04/G160 alone). Non-RT; stateless.

#include <array>
#include <string>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "gcode_lexer.hpp"

namespace edm::hmi::detail {

/// The words of one block, sorted by what they do; null where absent.
struct Block {
  int line{0};
  const Word* first{nullptr};
  const Word* motion_g{nullptr};        // group 1: G00 G01 G02 G03
  const Word* nonmodal_g{nullptr};      // group 0: G04 G160 G92 G92.1
  const Word* frame_g{nullptr};         // group 12: G54 .. G59
  const Word* plane_g{nullptr};         // group 2: G17
  const Word* units_g{nullptr};         // group 6: G20 G21
  const Word* distance_g{nullptr};      // group 3: G90 G91
  const Word* stop_m{nullptr};          // group 4: M00 M01 M02 M30
  const Word* comp_g{nullptr};          // group 7: G40 G41 G42 (wire offset)
  const Word* sub_m{nullptr};           // M98 M99 (subprogram call, return)
  const Word* rotation_m{nullptr};      // group 7: M03 M05
  const Word* flushing_m{nullptr};      // group 8: M08 M09
  std::array<const Word*, 26> value{};  // X Y Z I J F E P R D L O by letter

  [[nodiscard]] const Word* operator[](char letter) const noexcept {
    return value[static_cast<std::size_t>(letter - 'A')];
  }
  [[nodiscard]] const Word* first_axis() const noexcept {
    const Word* best = nullptr;
    for (char a : {'X', 'Y', 'Z'}) {
      const Word* w = (*this)[a];
      if (w != nullptr && (best == nullptr || w->col < best->col)) best = w;
    }
    return best;
  }
};

/// A G/M number × 10 (G01 → 10, G160 → 1600), or -1 when not a plausible code.
int code10(const Word& w) noexcept;

/// "'G05'": the word as written, quoted, for messages.
std::string word_text(const Word& w);

/// True for whole numbers of magnitude below 1e9 (N, E, P turns).
bool is_whole(double v) noexcept;

/// Sorts `words` (one line, at least one word) into `b`. False, with errors appended in column
/// order of discovery, when a rule is broken; the block must then not be executed.
bool sort_block(const std::vector<Word>& words, int line, Block& b,
                std::vector<GcodeError>& errors);

}  // namespace edm::hmi::detail
