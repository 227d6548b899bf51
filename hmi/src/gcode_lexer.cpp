// G-code lexer: words, comments, '%' lines. See gcode_lexer.hpp and docs/gcode.md.

#include "gcode_lexer.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace edm::hmi::detail {
namespace {

constexpr std::size_t kMaxNumberChars = 24;  // "-12345.678901234567890" and then some

bool is_letter(char c) noexcept { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }
bool is_blank(char c) noexcept { return c == ' ' || c == '\t'; }
bool is_number_char(char c) noexcept { return is_digit(c) || c == '.' || c == '+' || c == '-'; }

/// [+-]? digits [. digits?] | [+-]? . digits — RS274/NGC's decimal, no exponent.
bool well_formed(std::string_view s) noexcept {
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  int digits = 0;
  int points = 0;
  for (; i < s.size(); ++i) {
    if (is_digit(s[i])) {
      ++digits;
    } else if (s[i] == '.') {
      ++points;
    } else {
      return false;  // a sign in the middle
    }
  }
  return digits > 0 && points <= 1;
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) ? c : '?';
  }
  return out + "'";
}

}  // namespace

std::string describe_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u > 0x20 && u < 0x7f) return std::string("'") + c + "'";
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(u));
  return buf;
}

LexedLine lex_line(std::string_view line, int line_no, std::vector<GcodeError>& errors) {
  LexedLine out;
  auto error = [&](std::size_t at, std::string msg) {
    errors.push_back({line_no, static_cast<int>(at) + 1, std::move(msg)});
  };
  bool after_percent_reported = false;
  std::size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    if (is_blank(c) || (c == '\r' && i + 1 == line.size())) {
      ++i;
      continue;
    }
    if (c == ';') break;  // comment to the end of the line
    if (c == '(') {
      std::size_t j = i + 1;
      while (j < line.size() && line[j] != ')' && line[j] != '(') ++j;
      if (j == line.size()) {
        error(i, "unclosed comment: '(' without ')' on the same line");
        break;
      }
      if (line[j] == '(') {
        error(j, "'(' inside a comment (comments do not nest)");
        // Skip to the closing parenthesis, if any, to keep lexing the rest of the line.
        while (j < line.size() && line[j] != ')') ++j;
        if (j == line.size()) break;
      }
      i = j + 1;
      continue;
    }
    if (c == ')') {
      error(i, "')' without '('");
      ++i;
      continue;
    }
    if (c == '%') {
      if (out.words.empty() && !out.percent) {
        out.percent = true;
        out.percent_col = static_cast<int>(i) + 1;
      } else {
        error(i, "'%' must be alone on its line (program delimiter)");
      }
      ++i;
      continue;
    }
    if (!is_letter(c)) {
      if (is_number_char(c)) {
        std::size_t j = i;
        while (j < line.size() && is_number_char(line[j])) ++j;
        error(i, "number " + quoted(line.substr(i, j - i)) + " without a letter");
        i = j;
      } else {
        error(i, "unexpected character " + describe_char(c));
        ++i;
      }
      continue;
    }
    // A word: letter, optional blanks, number.
    const char letter = static_cast<char>(c >= 'a' ? c - 'a' + 'A' : c);
    std::size_t j = i + 1;
    while (j < line.size() && is_blank(line[j])) ++j;
    const std::size_t num_begin = j;
    while (j < line.size() && is_number_char(line[j])) ++j;
    const std::string_view num = line.substr(num_begin, j - num_begin);
    const std::string_view text = line.substr(i, j - i);
    if (out.percent && !after_percent_reported) {
      error(i, "'%' must be alone on its line (program delimiter)");
      after_percent_reported = true;
    }
    if (num.empty()) {
      error(i, std::string("missing number after '") + letter + "'");
      i = j;
      continue;
    }
    if (num.size() > kMaxNumberChars) {
      error(i, "number too long in " + quoted(text.substr(0, 1 + kMaxNumberChars)) + "...");
      i = j;
      continue;
    }
    if (!well_formed(num)) {
      error(i, "malformed number in " + quoted(text));
      i = j;
      continue;
    }
    std::string_view digits = num;
    if (digits.front() == '+') digits.remove_prefix(1);
    double value = 0.0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value)) {
      error(i, "malformed number in " + quoted(text));
      i = j;
      continue;
    }
    out.words.push_back(
        {letter, value, text, static_cast<int>(i) + 1, num.find('.') != std::string_view::npos});
    i = j;
  }
  return out;
}

}  // namespace edm::hmi::detail
