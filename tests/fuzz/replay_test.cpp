// Replays every committed fuzz input through the same entry functions the libFuzzer executables
// use: tests/fuzz/regressions/<target>/ (each a crash libFuzzer once found, kept fixed) and the
// seed corpora tests/fuzz/corpus/<target>/. A broken invariant aborts (EDM_FUZZ_CHECK); an
// escaping exception fails the test. Under ./edm sanitize they run with ASan+UBSan as well.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_entry.hpp"

namespace edm::fuzz {
namespace {

namespace fs = std::filesystem;
using Entry = int (*)(const std::uint8_t*, std::size_t);

std::vector<fs::path> inputs_of(const std::string& folder) {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(EDM_TEST_DATA_DIR) / "fuzz" / folder;
  if (fs::is_directory(dir)) {
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
      if (e.is_regular_file() && e.path().filename() != "README.md") {
        out.push_back(e.path());
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Returns how many inputs ran.
std::size_t replay(const std::string& target, Entry entry) {
  std::size_t n = 0;
  for (const char* kind : {"regressions/", "corpus/"}) {
    for (const fs::path& p : inputs_of(kind + target)) {
      SCOPED_TRACE(p.string());
      const std::string bytes = read_bytes(p);
      EXPECT_EQ(entry(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
      ++n;
    }
  }
  return n;
}

TEST(FuzzReplay, gcode_seeds_and_regressions_run_clean) {
  EXPECT_GT(replay("gcode", gcode_one_input), 0u);
}

TEST(FuzzReplay, config_seeds_and_regressions_run_clean) {
  EXPECT_GT(replay("config", config_one_input), 0u);
}

TEST(FuzzReplay, retain_seeds_and_regressions_run_clean) {
  EXPECT_GT(replay("retain", retain_one_input), 0u);
}

TEST(FuzzReplay, protocol_seeds_and_regressions_run_clean) {
  EXPECT_GT(replay("protocol", protocol_one_input), 0u);
}

TEST(FuzzReplay, page_seeds_and_regressions_run_clean) {
  EXPECT_GT(replay("page", page_one_input), 0u);
}

TEST(FuzzReplay, empty_input_runs_clean_everywhere) {
  for (Entry entry :
       {gcode_one_input, config_one_input, retain_one_input, protocol_one_input, page_one_input}) {
    EXPECT_EQ(entry(nullptr, 0), 0);
  }
}

}  // namespace
}  // namespace edm::fuzz
