// Input<T>::claim()/drive(): a composite writes its child's input directly (issue 32), and the
// ranking of what an input reads stays supervisor > force > the driven value.

#include <gtest/gtest.h>

#include <cstdint>

#include "edm/runtime/pin.hpp"

namespace edm::test {
namespace {

TEST(PinDrive, AClaimedInputReadsWhatItsOwnerDrivesAndNotItsFormerWire) {
  rt::Output<double> wire{5.0};
  rt::Input<double> in{1.0};
  in.connect(wire);
  EXPECT_EQ(in.get(), 5.0);
  in.claim(2.0);
  EXPECT_TRUE(in.claimed());
  EXPECT_TRUE(in.connected()) << "a driven input is not an unwired one";
  EXPECT_EQ(in.get(), 2.0) << "the claim's initial value, not the wire";
  wire.set(7.0);
  EXPECT_EQ(in.get(), 2.0);
  in.drive(3.5);
  EXPECT_EQ(in.get(), 3.5);
  EXPECT_EQ(in.requested(), 3.5);
  EXPECT_EQ(in.driven(), 3.5);
}

TEST(PinDrive, ForceAndSupervisionRankAboveTheDrivenValue) {
  rt::Input<std::int64_t> in;
  in.claim();
  in.drive(4);
  in.force(9);
  EXPECT_EQ(in.get(), 9);
  in.drive(5);  // the owner keeps driving while forced
  EXPECT_EQ(in.get(), 9);
  EXPECT_EQ(in.driven(), 5);
  in.supervise(-1);
  EXPECT_EQ(in.get(), -1);
  EXPECT_EQ(in.requested(), 9);
  in.end_supervision();
  in.unforce();
  EXPECT_EQ(in.get(), 5) << "back to the last driven value at once";
}

TEST(PinDrive, WiringAgainEndsTheClaim) {
  rt::Output<bool> wire{true};
  rt::Input<bool> in;
  in.claim(false);
  in.connect(wire);
  EXPECT_FALSE(in.claimed());
  EXPECT_TRUE(in.get());
  in.claim(false);
  in.set_constant(true);
  EXPECT_FALSE(in.claimed());
  EXPECT_FALSE(in.connected());
  EXPECT_TRUE(in.get());
}

}  // namespace
}  // namespace edm::test
