#include "edm/blocks/fuzzy_mamdani.hpp"

// The text of the fuzzy blocks' parameters: term lists and rules, parsed once at configure time
// (non-RT) with line:column errors. The inference engine is fuzzy_mamdani.cpp.

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace edm::blocks::fuzzy {
namespace {

bool ident_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
bool ident_char(char c) { return ident_start(c) || (c >= '0' && c <= '9'); }
bool blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string join_terms(const Variable& v) {
  std::string out;
  for (const auto& t : v.terms) {
    out += (out.empty() ? "" : ", ") + t.name;
  }
  return out;
}

// A cursor over the text that knows its line and column, for error messages.
class Cursor {
 public:
  Cursor(std::string_view text, SyntaxError& err) : text_(text), err_(err) {}

  void skip_blanks() {
    while (pos_ < text_.size() && blank(text_[pos_])) {
      ++pos_;
    }
  }
  [[nodiscard]] bool at_end() {
    skip_blanks();
    return pos_ >= text_.size();
  }
  [[nodiscard]] char peek() {
    skip_blanks();
    return pos_ < text_.size() ? text_[pos_] : '\0';
  }
  /// Offset of the next token (blanks skipped).
  [[nodiscard]] std::size_t pos() {
    skip_blanks();
    return pos_;
  }

  /// The next token as written (identifier, number or one character), for "found ..." messages.
  [[nodiscard]] std::string found() {
    skip_blanks();
    if (pos_ >= text_.size()) {
      return "the end of the text";
    }
    std::size_t end = pos_ + 1;
    if (ident_start(text_[pos_])) {
      while (end < text_.size() && ident_char(text_[end])) {
        ++end;
      }
    }
    return quoted(text_.substr(pos_, end - pos_));
  }

  /// The identifier at the cursor without consuming it (empty if none).
  [[nodiscard]] std::string_view peek_ident() {
    skip_blanks();
    std::size_t end = pos_;
    while (end < text_.size() && ident_char(text_[end])) {
      ++end;
    }
    return text_.substr(pos_, end - pos_);
  }
  /// Reads an identifier, or reports "expected <what>".
  std::optional<std::string_view> ident(std::string_view what) {
    skip_blanks();
    if (pos_ >= text_.size() || !ident_start(text_[pos_])) {
      fail(pos_, "expected " + std::string(what) + ", found " + found());
      return std::nullopt;
    }
    const std::size_t start = pos_;
    while (pos_ < text_.size() && ident_char(text_[pos_])) {
      ++pos_;
    }
    return text_.substr(start, pos_ - start);
  }
  /// Reads the keyword `kw` (a whole identifier).
  bool keyword(std::string_view kw) {
    skip_blanks();
    const std::size_t start = pos_;
    std::size_t end = pos_;
    while (end < text_.size() && ident_char(text_[end])) {
      ++end;
    }
    if (text_.substr(start, end - start) != kw) {
      fail(start, "expected " + quoted(kw) + ", found " + found());
      return false;
    }
    pos_ = end;
    return true;
  }
  /// Reads the character c.
  bool expect(char c) {
    if (peek() != c) {
      fail(pos_, "expected " + quoted(std::string_view(&c, 1)) + ", found " + found());
      return false;
    }
    ++pos_;
    return true;
  }
  /// Reads a finite number.
  std::optional<double> number() {
    skip_blanks();
    const char* b = text_.data() + pos_;
    const char* e = text_.data() + text_.size();
    double v = 0.0;
    auto [p, ec] = std::from_chars(b, e, v);
    if (ec != std::errc{} || p == b || !std::isfinite(v)) {
      fail(pos_, "expected a number, found " + found());
      return std::nullopt;
    }
    pos_ += static_cast<std::size_t>(p - b);
    return v;
  }

  /// Records an error at `offset` (the first error wins).
  void fail(std::size_t offset, const std::string& msg) {
    if (failed_) {
      return;
    }
    failed_ = true;
    int line = 1;
    int col = 1;
    for (std::size_t i = 0; i < offset && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    err_.offset = offset;
    err_.line = line;
    err_.column = col;
    err_.message =
        "at line " + std::to_string(line) + ", column " + std::to_string(col) + ": " + msg;
  }

 private:
  std::string_view text_;
  SyntaxError& err_;
  std::size_t pos_{0};
  bool failed_{false};
};

}  // namespace

std::optional<std::vector<Term>> parse_terms(std::string_view text, SyntaxError& err) {
  Cursor cur(text, err);
  std::vector<Term> terms;
  while (true) {
    while (cur.peek() == ',' || cur.peek() == ';') {
      cur.expect(cur.peek());
    }
    if (cur.at_end()) {
      break;
    }
    const std::size_t name_pos = cur.pos();
    auto name = cur.ident("a term name");
    if (!name) {
      return std::nullopt;
    }
    for (const auto& t : terms) {
      if (t.name == *name) {
        cur.fail(name_pos, "term " + quoted(*name) + " defined twice");
        return std::nullopt;
      }
    }
    if (!cur.expect('=')) {
      return std::nullopt;
    }
    const std::size_t shape_pos = cur.pos();
    auto shape = cur.ident("'tri' or 'trap'");
    if (!shape) {
      return std::nullopt;
    }
    Term t;
    t.name = std::string(*name);
    std::size_t n = 0;
    if (*shape == "tri") {
      t.shape = Term::Shape::kTri;
      n = 3;
    } else if (*shape == "trap") {
      t.shape = Term::Shape::kTrap;
      n = 4;
    } else {
      cur.fail(shape_pos, "expected 'tri' or 'trap', found " + quoted(*shape));
      return std::nullopt;
    }
    if (!cur.expect('(')) {
      return std::nullopt;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0 && !cur.expect(',')) {
        return std::nullopt;
      }
      auto v = cur.number();
      if (!v) {
        return std::nullopt;
      }
      t.p[i] = *v;
    }
    if (!cur.expect(')')) {
      return std::nullopt;
    }
    bool ordered = t.p[0] < t.p[n - 1];
    for (std::size_t i = 1; i < n; ++i) {
      ordered = ordered && t.p[i - 1] <= t.p[i];
    }
    if (!ordered) {
      cur.fail(shape_pos, "term " + quoted(t.name) + ": " + std::string(*shape) +
                              (n == 3 ? "(a,b,c) needs a <= b <= c and a < c"
                                      : "(a,b,c,d) needs a <= b <= c <= d and a < d"));
      return std::nullopt;
    }
    terms.push_back(std::move(t));
  }
  if (terms.empty()) {
    cur.fail(0, "no terms (expected e.g. 'Z=tri(0,0,8) L=trap(8,16,32,32)')");
    return std::nullopt;
  }
  return terms;
}

std::optional<std::vector<Rule>> parse_rules(std::string_view text,
                                             std::span<const Variable> inputs,
                                             const Variable& output, SyntaxError& err) {
  Cursor cur(text, err);
  std::vector<Rule> rules;
  // Reads "<var> is <term>" for an input (var_index ≥ 0) or the output.
  const auto clause = [&](bool is_output, int& var_index, int& term_index) {
    const std::size_t var_pos = cur.pos();
    auto var = cur.ident(is_output ? "the output variable" : "an input variable");
    if (!var) {
      return false;
    }
    const Variable* v = nullptr;
    if (is_output) {
      if (*var != output.name) {
        cur.fail(var_pos,
                 "the output variable is " + quoted(output.name) + ", found " + quoted(*var));
        return false;
      }
      v = &output;
    } else {
      std::string names;
      for (std::size_t i = 0; i < inputs.size(); ++i) {
        names += (names.empty() ? "" : ", ") + inputs[i].name;
        if (inputs[i].name == *var) {
          var_index = static_cast<int>(i);
          v = &inputs[i];
        }
      }
      if (v == nullptr) {
        cur.fail(var_pos, "unknown input variable " + quoted(*var) + " (inputs: " + names + ")");
        return false;
      }
    }
    if (!cur.keyword("is")) {
      return false;
    }
    const std::size_t term_pos = cur.pos();
    auto term = cur.ident("a term name");
    if (!term) {
      return false;
    }
    term_index = v->find(*term);
    if (term_index < 0) {
      cur.fail(term_pos, "unknown term " + quoted(*term) + " of " + quoted(v->name) +
                             " (terms: " + (v->terms.empty() ? "none" : join_terms(*v)) + ")");
      return false;
    }
    return true;
  };

  while (!cur.at_end()) {
    Rule r;
    if (!cur.keyword("if")) {
      return std::nullopt;
    }
    while (true) {
      Rule::Clause c;
      if (!clause(false, c.var, c.term)) {
        return std::nullopt;
      }
      r.clauses.push_back(c);
      const std::string_view next = cur.peek_ident();
      if (next == "then") {
        break;
      }
      if (next != "and") {
        cur.fail(cur.pos(), "expected 'and' or 'then', found " + cur.found());
        return std::nullopt;
      }
      cur.keyword("and");
    }
    cur.keyword("then");
    int unused = 0;
    if (!clause(true, unused, r.out_term)) {
      return std::nullopt;
    }
    rules.push_back(std::move(r));
    if (cur.at_end()) {
      break;
    }
    if (!cur.expect(';')) {
      return std::nullopt;
    }
  }
  if (rules.empty()) {
    cur.fail(0, "no rules (expected e.g. 'if open is L and short is Z then v is PB')");
    return std::nullopt;
  }
  return rules;
}

}  // namespace edm::blocks::fuzzy
