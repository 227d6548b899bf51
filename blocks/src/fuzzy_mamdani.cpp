#include "edm/blocks/fuzzy_mamdani.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace edm::blocks::fuzzy {

double Term::membership(double x) const noexcept {
  if (shape == Shape::kTri) {
    const double a = p[0], b = p[1], c = p[2];
    if (x < a || x > c) {
      return 0.0;
    }
    if (x == b) {
      return 1.0;
    }
    return x < b ? (x - a) / (b - a) : (c - x) / (c - b);
  }
  const double a = p[0], b = p[1], c = p[2], d = p[3];
  if (x < a || x > d) {
    return 0.0;
  }
  if (x >= b && x <= c) {
    return 1.0;
  }
  return x < b ? (x - a) / (b - a) : (d - x) / (d - c);
}

int Variable::find(std::string_view term) const noexcept {
  for (std::size_t i = 0; i < terms.size(); ++i) {
    if (terms[i].name == term) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

MamdaniEngine::MamdaniEngine(std::vector<Variable> inputs, Variable output, std::vector<Rule> rules,
                             std::size_t samples)
    : inputs_(std::move(inputs)), output_(std::move(output)), rules_(std::move(rules)) {
  lo_ = std::numeric_limits<double>::infinity();
  hi_ = -std::numeric_limits<double>::infinity();
  for (const auto& t : output_.terms) {
    lo_ = std::min(lo_, t.lo());
    hi_ = std::max(hi_, t.hi());
  }
  const std::size_t n = std::max<std::size_t>(samples, 3);
  grid_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    // lo + j·step, with the end point exact.
    grid_[j] =
        j + 1 == n ? hi_ : lo_ + (hi_ - lo_) * static_cast<double>(j) / static_cast<double>(n - 1);
  }
  out_mu_.assign(output_.terms.size(), std::vector<double>(n, 0.0));
  for (std::size_t t = 0; t < output_.terms.size(); ++t) {
    for (std::size_t j = 0; j < n; ++j) {
      out_mu_[t][j] = output_.terms[t].membership(grid_[j]);
    }
  }
}

double MamdaniEngine::infer(std::span<const double> x) const {
  std::vector<double> agg(grid_.size(), 0.0);
  bool fired = false;
  for (const Rule& r : rules_) {
    double w = 1.0;
    for (const Rule::Clause& c : r.clauses) {
      const auto var = static_cast<std::size_t>(c.var);
      const double xv = var < x.size() ? x[var] : 0.0;
      w = std::min(w, inputs_[var].terms[static_cast<std::size_t>(c.term)].membership(xv));
    }
    if (w <= 0.0) {
      continue;
    }
    fired = true;
    const auto& mu = out_mu_[static_cast<std::size_t>(r.out_term)];
    for (std::size_t j = 0; j < agg.size(); ++j) {
      agg[j] = std::max(agg[j], std::min(w, mu[j]));
    }
  }
  double num = 0.0;
  double den = 0.0;
  for (std::size_t j = 0; j < agg.size(); ++j) {
    num += grid_[j] * agg[j];
    den += agg[j];
  }
  if (!fired || den <= 0.0) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return num / den;
}

}  // namespace edm::blocks::fuzzy
