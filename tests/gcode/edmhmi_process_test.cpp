// Runs the edmhmi binary: `check` on good and bad part programs, the not-yet-available bridge
// commands and bad arguments, checking exit codes and output (DESIGN §4).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "support/subprocess.hpp"
#include "support/temp_dir.hpp"

namespace edm::hmi::test {
namespace {

struct Outcome {
  int code{-1};
  std::string output;  // stdout and stderr together
};

Outcome edmhmi(const std::vector<std::string>& args) {
  std::vector<std::string> argv{EDM_EDMHMI_PATH};
  argv.insert(argv.end(), args.begin(), args.end());
  edm::test::Child child(argv);
  Outcome r;
  r.code = child.wait();
  r.output = child.output();
  return r;
}

const std::string kParts = std::string(EDM_SOURCE_DIR) + "/examples/parts/";

TEST(EdmhmiCheck, GoodProgramPrintsASummaryAndExitsZero) {
  const Outcome r = edmhmi({"check", kParts + "blind-hole.nc"});
  EXPECT_EQ(r.code, 0) << r.output;
  // drill-sim.yaml's E1: θ 0.6189, A_hole/A_e 1.3297; 20 mm below the surface (eq. 10).
  EXPECT_NE(r.output.find("blind-hole.nc: ok: 12 blocks, 1 drilling blocks, 20.000 mm drilled, "
                          "estimated electrode wear 16.459 mm"),
            std::string::npos)
      << r.output;
}

TEST(EdmhmiCheck, BadProgramPrintsLocatedErrorsAndExitsTwo) {
  edm::test::TempDir dir;
  const std::string part = dir.file("bad.nc");
  std::ofstream(part) << "G00 X0\nG18\nG00 X500\nM30\n";
  const Outcome r = edmhmi({"check", part});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find(part + ":2:1: 'G18' is not supported"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(part + ":3:5: X 500.000 mm is beyond the X soft limit"),
            std::string::npos)
      << r.output;
}

// Issue 34: on the wire machine the shipped punch passes and a program whose wire offset cannot be
// applied (a concave arc smaller than E1's 0.2 mm offset) is refused at the arc's line:col.
TEST(EdmhmiCheck, AWireOffsetThatCannotBeAppliedIsRefusedAtItsLine) {
  const std::string wire = std::string(EDM_SOURCE_DIR) + "/config/machines/wire-sim.yaml";
  const Outcome ok = edmhmi({"check", "--machine", wire, kParts + "wire-punch.nc"});
  EXPECT_EQ(ok.code, 0) << ok.output;
  edm::test::TempDir dir;
  const std::string part = dir.file("pocket.nc");
  std::ofstream(part) << "G00 X-9 Y0\nE1 F3\nG41 G01 X-5 Y0\n  G03 X-5.2 Y0.2 I0 J0.2\n"
                         "G40 G01 X-9 Y0\nE0\nM30\n";
  const Outcome r = edmhmi({"check", "--machine", wire, part});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find(part + ":4:3: the wire offset 0.200 mm cannot be applied: this concave "
                                 "arc's radius 0.200 mm is not larger than the offset"),
            std::string::npos)
      << r.output;
}

TEST(EdmhmiCheck, MachineOptionSelectsTheConditionTable) {
  // sink-sim has no E2: the finishing example is refused there.
  const std::string sink = std::string(EDM_SOURCE_DIR) + "/config/machines/sink-sim.yaml";
  const Outcome r = edmhmi({"check", "--machine", sink, kParts + "drill-then-finish.nc"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(
      r.output.find("drill-then-finish.nc:13:1: unknown condition 'E2' (this machine has E1)"),
      std::string::npos)
      << r.output;
  const Outcome bad =
      edmhmi({"check", "--machine", "/nonexistent/m.yaml", kParts + "blind-hole.nc"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("/nonexistent/m.yaml:1:1: cannot open"), std::string::npos)
      << bad.output;
}

TEST(EdmhmiCheck, MissingPartFileIsBadInput) {
  const Outcome r = edmhmi({"check", "/nonexistent/part.nc"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("/nonexistent/part.nc:1:1: cannot open"), std::string::npos) << r.output;
}

// Issue 17 item 10: whatever the path names, `check` answers at once with a located error and
// exit 2: a directory, a FIFO (no writer: a blocking open would hang), a device that never ends
// (/dev/zero: reading it whole would exhaust memory), a part program over 64 MiB, and the same
// kinds of file given as --machine.
TEST(EdmhmiCheck, NonRegularOrHugeInputIsALocatedErrorNotAHangOrACrash) {
  edm::test::TempDir dir;
  const std::string fifo = dir.file("part.nc");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string huge = dir.file("huge.nc");
  { std::ofstream(huge) << "G00 X0\n"; }
  std::filesystem::resize_file(huge, std::uintmax_t{1} << 40);  // sparse 1 TiB
  const std::string d = dir.path().string();
  const std::vector<std::pair<std::string, std::string>> parts = {
      {d, d + ":1:1: not a regular file (a directory)"},
      {fifo, fifo + ":1:1: not a regular file (a FIFO)"},
      {"/dev/zero", "/dev/zero:1:1: not a regular file (a device)"},
      {huge, huge + ":1:1: part program is 1099511627776 bytes; the limit is 64 MiB"},
  };
  for (const auto& [path, message] : parts) {
    const Outcome r = edmhmi({"check", path});
    EXPECT_EQ(r.code, 2) << path << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    const Outcome m = edmhmi({"check", "--machine", path, kParts + "blind-hole.nc"});
    EXPECT_EQ(m.code, 2) << path << ": " << m.output;
    EXPECT_NE(m.output.find(path + ":1:1: "), std::string::npos) << m.output;
  }
}

TEST(EdmhmiCommands, BridgeCommandsWithoutEdmplcFailWithExitOne) {
  // Port 1 on loopback: nothing listens there, the connection is refused at once.
  for (const std::vector<std::string>& c :
       {std::vector<std::string>{"status"}, {"run", kParts + "blind-hole.nc"}, {"estop"}}) {
    std::vector<std::string> args = {"--host", "127.0.0.1", "--port", "1"};
    args.insert(args.end(), c.begin(), c.end());
    const Outcome r = edmhmi(args);
    EXPECT_EQ(r.code, 1) << c[0];
    EXPECT_NE(r.output.find("edmhmi: edmplc at 127.0.0.1:1:"), std::string::npos) << r.output;
  }
}

TEST(EdmhmiCommands, BadArgumentsPrintUsageAndExitTwo) {
  for (const std::vector<std::string>& args : {std::vector<std::string>{},
                                               {"frobnicate"},
                                               {"check"},
                                               {"check", "a.nc", "b.nc"},
                                               {"--bogus", "check", "a.nc"},
                                               {"check", "--machine"}}) {
    const Outcome r = edmhmi(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("usage: edmhmi"), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace edm::hmi::test
