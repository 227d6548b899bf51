// Every registered block type must be usable from a config: its pin and parameter names become
// variables `program.block.<name>`, so no name may be both a pin and a parameter, or appear twice.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {
namespace {

class Names final : public rt::PinVisitor, public rt::ParamVisitor {
 public:
  std::set<std::string> seen;
  std::vector<std::string> duplicates;

 protected:
  void on_pin(std::string_view name, rt::PinRef, std::string_view) override { add(name); }
  void on_param(std::string_view name, rt::ParamRef, rt::ParamInfo) override { add(name); }

 private:
  void add(std::string_view name) {
    if (!seen.emplace(name).second) {
      duplicates.emplace_back(name);
    }
  }
};

TEST(BlockRegistry, NoPinOrParameterNameIsUsedTwiceInAnyBlockType) {
  rt::BlockRegistry r;
  register_builtin_blocks(r);
  ASSERT_GE(r.names().size(), 15u);
  for (const std::string& type : r.names()) {
    auto block = r.create(type);
    ASSERT_NE(block, nullptr) << type;
    // Pins may depend on configure(); this list covers blocks whose pins are fixed at creation.
    Names n;
    block->visit_params(static_cast<rt::ParamVisitor&>(n));
    block->visit_pins(static_cast<rt::PinVisitor&>(n));
    EXPECT_TRUE(n.duplicates.empty())
        << type << ": name(s) used twice: " << ::testing::PrintToString(n.duplicates);
  }
}

}  // namespace
}  // namespace edm::blocks
