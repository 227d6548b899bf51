#pragma once
// Shared by the fuzzy tests: a fuzzy variable from its term text (a test failure if it does not
// parse).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "edm/blocks/fuzzy_mamdani.hpp"

namespace edm::blocks::test {

inline fuzzy::Variable variable(const std::string& name, const std::string& text) {
  fuzzy::SyntaxError err;
  auto terms = fuzzy::parse_terms(text, err);
  EXPECT_TRUE(terms.has_value()) << err.message;
  return {name, terms.value_or(std::vector<fuzzy::Term>{})};
}

}  // namespace edm::blocks::test
