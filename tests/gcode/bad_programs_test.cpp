// Every part program under tests/gcode/bad/ is refused, and its first error is the one named
// on its first line: "; expect: NAME.nc:line:col: message prefix".
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> bad_programs() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(fs::path(EDM_TEST_DATA_DIR) / "gcode" / "bad")) {
    if (e.path().extension() == ".nc") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(GcodeBadPrograms, ThereAreAtLeastTwenty) { EXPECT_GE(bad_programs().size(), 20u); }

TEST(GcodeBadPrograms, EachIsRefusedWithItsExpectedFirstError) {
  const std::string kTag = "; expect: ";
  for (const fs::path& p : bad_programs()) {
    SCOPED_TRACE(p.filename().string());
    const std::string text = read(p);
    ASSERT_EQ(text.rfind(kTag, 0), 0u) << "first line must be '" << kTag << "...'";
    const std::string expect = text.substr(kTag.size(), text.find('\n') - kTag.size());
    ASSERT_FALSE(expect.empty());
    const GcodeResult r = interpret_gcode(text, p.filename().string(), test_tables());
    ASSERT_FALSE(r.ok());
    EXPECT_TRUE(r.blocks.empty());
    const std::string first = r.messages().front();
    EXPECT_EQ(first.substr(0, expect.size()), expect) << "all errors:\n" << joined(r);
  }
}

}  // namespace
}  // namespace edm::hmi::test
