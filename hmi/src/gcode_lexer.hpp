#pragma once
// Private to the interpreter: splits one G-code line into words (letter + number), dropping
// comments and whitespace and reporting malformed text. Non-RT; stateless functions.

#include <string>
#include <string_view>
#include <vector>

#include "edm/hmi/gcode.hpp"

namespace edm::hmi::detail {

/// One word of a block, e.g. "G01" or "X-12.5".
struct Word {
  char letter{'?'};       // upper case
  double value{0.0};      // the number, finite
  std::string_view text;  // the word as written (letter and number), for messages
  int col{0};             // 1-based column of the letter
  bool has_point{false};  // the number was written with a decimal point
};

struct LexedLine {
  std::vector<Word> words;
  bool percent{false};  // the line is a '%' program delimiter (nothing else but comments)
  int percent_col{0};
};

/// Lexes `line` (without its line end). Errors go to `errors` with line number `line_no`;
/// words with errors are left out of the result.
LexedLine lex_line(std::string_view line, int line_no, std::vector<GcodeError>& errors);

/// A byte for a message: 'c' when printable ASCII, else 0xNN.
std::string describe_char(char c);

}  // namespace edm::hmi::detail
