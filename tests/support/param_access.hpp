#pragma once
// Runtime parameter access in tests, the way the variable registry does it: a parameter is found
// by name in visit order (a C++ PROGRAM's child parameters as "child.param"), staged (non-RT,
// validated on the shadow copy) and, if accepted, applied before the next cycle.

#include <gtest/gtest.h>

#include <cstddef>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::test {

/// Index of parameter `name` for stage_param/apply_param/read_param (visit order); a test
/// failure and SIZE_MAX when there is none.
inline std::size_t param_index(rt::Block& block, std::string_view name) {
  struct Find final : rt::ParamVisitor {
    std::string_view want;
    std::size_t n{0};
    std::size_t found{static_cast<std::size_t>(-1)};
    void on_param(std::string_view pname, rt::ParamRef, rt::ParamSpec) override {
      if (pname == want) {
        found = n;
      }
      ++n;
    }
  } f;
  f.want = name;
  block.visit_params(f);
  EXPECT_NE(f.found, static_cast<std::size_t>(-1)) << "no parameter '" << name << "'";
  return f.found;
}

/// Stages and, if accepted, applies a runtime write. Returns stage_param's errors.
inline std::vector<rt::ParamError> write_param(rt::Block& block, std::string_view name,
                                               const rt::ParamValue& v) {
  const std::size_t index = param_index(block, name);
  auto errs = block.stage_param(index, v);
  if (errs.empty()) {
    block.apply_param(index, v);
  }
  return errs;
}

}  // namespace edm::test
