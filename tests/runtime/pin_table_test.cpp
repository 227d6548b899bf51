// Named pins: a pin declared with its owner's table lists itself there, once, with its unit and
// in declaration order; its default value still holds; a group of pins (PulseInputs-style)
// constructed on the owner's table lists with the owner's own pins; an axis triple (Xyz) lists its
// three pins in X, Y, Z order, each the very element the block indexes.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/pin.hpp"
#include "edm/runtime/xyz_pins.hpp"

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

class Axes final : public Block {
 public:
  BlockStatus update(const CycleContext& /*ctx*/) noexcept override { return BlockStatus::kOk; }

  Input<bool> enable{pins_, "enable"};
  Xyz<Input<double>> pos{pins_, {"x_mm", "y_mm", "z_mm"}, "mm"};
  Xyz<Output<bool>> set{pins_, {"set_x", "set_y", "set_z"}};
};

TEST(PinTable, AnAxisTripleListsXYZInOrderAndEachListedPinIsTheElementIndexed) {
  struct Refs final : PinVisitor {
    std::vector<std::string> rows;
    std::vector<PinRef> refs;
    void on_pin(std::string_view name, PinRef ref, std::string_view unit) override {
      rows.push_back(std::string(name) + " [" + std::string(unit) + "]");
      refs.push_back(ref);
    }
  } r;
  Axes block;
  block.visit_pins(r);
  const std::vector<std::string> expected = {"enable []", "x_mm [mm]", "y_mm [mm]", "z_mm [mm]",
                                             "set_x []",  "set_y []",  "set_z []"};
  ASSERT_EQ(r.rows, expected);
  for (std::size_t a = 0; a < kAxes; ++a) {
    EXPECT_EQ(r.refs[1 + a].as_input<double>(), &block.pos[a]) << a;
    EXPECT_EQ(r.refs[4 + a].as_output<bool>(), &block.set[a]) << a;
  }
  EXPECT_EQ(&block.pos.z(), &block.pos[kAxisZ]);
  // A write through the table is what the block reads on that axis, and on no other.
  block.set.y().set(true);
  EXPECT_DOUBLE_EQ(read_pin_as_double(r.refs[5]), 1.0);
  EXPECT_DOUBLE_EQ(read_pin_as_double(r.refs[4]), 0.0);
  EXPECT_DOUBLE_EQ(read_pin_as_double(r.refs[6]), 0.0);
}

}  // namespace
}  // namespace edm::rt
