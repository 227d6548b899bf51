#include "edm/blocks/register.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::blocks {
namespace {

struct PinList final : rt::PinVisitor {
  std::vector<std::pair<std::string, rt::PinRef>> pins;
  void on_pin(std::string_view name, rt::PinRef ref, std::string_view /*unit*/) override {
    pins.emplace_back(std::string(name), ref);
  }
  [[nodiscard]] std::string signature() const {
    std::string s;
    for (const auto& [name, ref] : pins) {
      s += (ref.dir == rt::PinDir::kInput ? "in:" : "out:") + name + ":" +
           std::string(rt::to_string(ref.type)) + " ";
    }
    return s;
  }
};

TEST(RegisterTest, every_generic_block_is_registered_with_its_pins) {
  rt::BlockRegistry r;
  register_builtin_blocks(r);
  const std::pair<const char*, const char*> expected[] = {
      {"Gain", "in:in:LREAL out:out:LREAL "},
      {"LowPass", "in:in:LREAL out:out:LREAL "},
      {"Limiter", "in:in:LREAL out:out:LREAL out:limited:BOOL "},
      {"MovingAverage", "in:in:LREAL out:out:LREAL out:full:BOOL "},
      {"SineSource", "out:out:LREAL "},
      {"Integrator", "in:in:LREAL in:reset:BOOL out:out:LREAL "},
  };
  for (const auto& [type, pins] : expected) {
    auto block = r.create(type);
    ASSERT_NE(block, nullptr) << type;
    EXPECT_FALSE(r.entries().at(type).summary.empty()) << type;
    PinList list;
    block->visit_pins(list);
    EXPECT_EQ(list.signature(), pins) << type;
    EXPECT_TRUE(block->validate().empty()) << type << ": defaults must be valid";
  }
}

}  // namespace
}  // namespace edm::blocks
