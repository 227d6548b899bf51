// Named pins: a pin declared with its owner's table lists itself there, once, with its unit and
// in declaration order; its default value still holds; a group of pins (PulseInputs-style)
// constructed on the owner's table lists with the owner's own pins.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/pin.hpp"

namespace edm::rt {
namespace {

struct Listed final : PinVisitor {
  std::vector<std::string> rows;
  void on_pin(std::string_view name, PinRef ref, std::string_view unit) override {
    rows.push_back(std::string(ref.dir == PinDir::kInput ? "in " : "out ") + std::string(name) +
                   " [" + std::string(unit) + "] " + std::string(to_string(ref.type)));
  }
};

struct Counters {
  explicit Counters(PinTable& owner) : a{owner, "a"}, b{owner, "b", "ns"} {}
  Input<std::int64_t> a;
  Input<std::int64_t> b;
};

class Named final : public Block {
 public:
  BlockStatus update(const CycleContext& /*ctx*/) noexcept override { return BlockStatus::kOk; }

  Input<double> x_mm{pins_, "x_mm", "mm"};
  Input<bool> enable{pins_, "enable", "", true};
  Counters counters{pins_};
  Output<double> v{pins_, "v_mm_s", "mm/s", 2.5};
  Output<bool> done{pins_, "done"};
};

TEST(PinTable, APinNamedWithItsTableIsListedOnceInDeclarationOrderWithItsUnit) {
  Named block;
  Listed l;
  block.visit_pins(l);
  const std::vector<std::string> expected = {
      "in x_mm [mm] LREAL", "in enable [] BOOL",       "in a [] LINT",
      "in b [ns] LINT",     "out v_mm_s [mm/s] LREAL", "out done [] BOOL"};
  EXPECT_EQ(l.rows, expected);
}

TEST(PinTable, DefaultsOfNamedPinsHold) {
  Named block;
  EXPECT_TRUE(block.enable.get());
  EXPECT_DOUBLE_EQ(block.v.get(), 2.5);
  EXPECT_DOUBLE_EQ(block.x_mm.get(), 0.0);
}

TEST(PinTable, TheListedReferenceIsTheMemberItself) {
  struct Refs final : PinVisitor {
    std::vector<PinRef> refs;
    void on_pin(std::string_view, PinRef ref, std::string_view) override { refs.push_back(ref); }
  } r;
  Named block;
  block.visit_pins(r);
  ASSERT_EQ(r.refs.size(), 6u);
  EXPECT_EQ(r.refs[0].as_input<double>(), &block.x_mm);
  EXPECT_EQ(r.refs[3].as_input<std::int64_t>(), &block.counters.b);
  EXPECT_EQ(r.refs[4].as_output<double>(), &block.v);
  block.v.set(7.0);
  EXPECT_DOUBLE_EQ(read_pin_as_double(r.refs[4]), 7.0);
}

}  // namespace
}  // namespace edm::rt
