#pragma once
// A small Mamdani fuzzy-inference engine and the text encoding of its terms and rules, used by
// FuzzyServoLUT (seed 003) to precompute its lookup table at load time.
//
// Terms (one string per variable), separated by blanks, ',' or ';':
//   Z=tri(-14,0,14) M=tri(0,14,32) L=trap(14,32,32,40)
//   tri(a,b,c):    0 outside [a,c], rises linearly a→b, 1 at b, falls b→c     (a ≤ b ≤ c, a < c)
//   trap(a,b,c,d): 0 outside [a,d], rises a→b, 1 on [b,c], falls c→d          (a ≤ b ≤ c ≤ d, a <
//   d) (a = b or c = d give a shoulder: μ = 1 at that edge and 0 beyond it.)
// Rules, separated by ';' (a trailing ';' is allowed, blanks and newlines are free):
//   if open is L and short is Z then v is PB; if open is Z and short is L then v is NB
//   keywords `if`, `and`, `is`, `then` in lower case; variable and term names are case-sensitive
//   identifiers [A-Za-z_][A-Za-z0-9_]*. Only AND (min) is supported: write OR as two rules.
// Errors name the position in the text as "at line L, column C" (1-based, within the string).
//
// Inference: rule strength w = min over its clauses of μ(x); implication clips the consequent at
// w (min); aggregation is max over rules; the crisp output is the centroid of the aggregated set
// sampled at `samples` equally spaced points spanning the union of the output terms' supports.
// A symmetric output term fired alone therefore gives exactly its peak (up to rounding). When no
// rule fires, infer() returns NaN.
//
// Non-RT and not RT-safe (allocates); thread-compatible (const members may run concurrently).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace edm::blocks::fuzzy {

struct Term {
  enum class Shape : std::uint8_t { kTri, kTrap };
  std::string name;
  Shape shape{Shape::kTri};
  double p[4]{0.0, 0.0, 0.0, 0.0};  // tri uses p[0..2]

  /// Membership degree μ(x) in [0, 1].
  [[nodiscard]] double membership(double x) const noexcept;
  /// Support [lo, hi] (μ = 0 outside).
  [[nodiscard]] double lo() const noexcept { return p[0]; }
  [[nodiscard]] double hi() const noexcept { return shape == Shape::kTri ? p[2] : p[3]; }
};

struct Variable {
  std::string name;
  std::vector<Term> terms;
  /// Index of the term called `name`, or -1.
  [[nodiscard]] int find(std::string_view term) const noexcept;
};

struct Rule {
  struct Clause {
    int var{0};   // index into the engine's inputs
    int term{0};  // index into that input's terms
  };
  std::vector<Clause> clauses;
  int out_term{0};
};

/// A problem in a term or rule text: its 0-based offset, 1-based line and column, and a message
/// that already starts with "at line L, column C: ".
struct SyntaxError {
  std::size_t offset{0};
  int line{1};
  int column{1};
  std::string message;
};

/// Parses a term list. On failure returns nullopt and fills `err`.
std::optional<std::vector<Term>> parse_terms(std::string_view text, SyntaxError& err);

/// Parses a rule list against the given input variables and output variable.
std::optional<std::vector<Rule>> parse_rules(std::string_view text,
                                             std::span<const Variable> inputs,
                                             const Variable& output, SyntaxError& err);

class MamdaniEngine {
 public:
  /// samples ≥ 3; the output terms must not be empty and their union support must have width > 0.
  MamdaniEngine(std::vector<Variable> inputs, Variable output, std::vector<Rule> rules,
                std::size_t samples);

  /// Crisp output for one input vector (x[i] is the value of inputs[i]); NaN if no rule fires.
  [[nodiscard]] double infer(std::span<const double> x) const;

  [[nodiscard]] const std::vector<Variable>& inputs() const noexcept { return inputs_; }
  [[nodiscard]] const Variable& output() const noexcept { return output_; }
  [[nodiscard]] const std::vector<Rule>& rules() const noexcept { return rules_; }
  [[nodiscard]] double universe_lo() const noexcept { return lo_; }
  [[nodiscard]] double universe_hi() const noexcept { return hi_; }

 private:
  std::vector<Variable> inputs_;
  Variable output_;
  std::vector<Rule> rules_;
  double lo_{0.0};
  double hi_{0.0};
  std::vector<double> grid_;                 // output universe samples
  std::vector<std::vector<double>> out_mu_;  // [term][sample]
};

}  // namespace edm::blocks::fuzzy
