// `machine.safety` problems the builder finds (the parser's are in tests/configs/bad/safety_*):
// pins that do not exist or have the wrong direction or type, each at its file:line:col.
#include <gtest/gtest.h>

#include <string>

#include "safety/safety_rig.hpp"

namespace edm::test {
namespace {

std::string first_error(const std::string& safety) {
  const std::string yaml = safety_machine(1) + safety + kGainTask;
  return first_build_error(yaml, "m.yaml");
}

TEST(SafetyConfig, VelocityMustBeAnLrealInputOfTheDriver) {
  EXPECT_EQ(first_error("    axes: [{name: Z, velocity: io.ai0, position: io.ai0}]"),
            "m.yaml:8:32: machine.safety: 'io.ai0' (velocity) must be a LREAL input (a command "
            "to the machine) of the I/O driver; it is a LREAL output");
}

TEST(SafetyConfig, WireBreakMustBeABoolOutput) {
  EXPECT_EQ(first_error("    wire_break: io.do0"),
            "m.yaml:8:17: machine.safety: 'io.do0' (wire_break) must be a BOOL output (a reading "
            "from the machine) of the I/O driver; it is a BOOL input");
}

TEST(SafetyConfig, UnknownPinListsTheDriversPins) {
  const std::string e = first_error("    generator: [io.gen_on]");
  EXPECT_EQ(e.rfind("m.yaml:8:17: 'io.gen_on': I/O driver 'io' has no pin 'gen_on'", 0), 0u) << e;
}

TEST(SafetyConfig, APinIsSupervisedOnce) {
  EXPECT_EQ(first_error("    generator: [io.do0, io.do0]"),
            "m.yaml:8:25: machine.safety.generator[1]: 'io.do0' is supervised twice (first at "
            "line 8)");
}

}  // namespace
}  // namespace edm::test
