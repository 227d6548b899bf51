// `include:` of a program (docs/config.md "Fragments"): a fragment's blocks and wires are appended
// to the program's, found relative to the including file; every error in a fragment is located
// in the fragment and names where it was included from; missing fragments, cycles, nesting, size
// and duplicate definitions are refused. And the shipped drill machines share one job wiring.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "edm/blocks/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

using edm::test::TempDir;
using edm::test::write_file;

// A program `p` with one block, on a loopback machine; `program_tail` goes under the program
// (lines 11 on, indented 4).
std::string config_with(const std::string& program_tail) {
  return "version: 1\n"                                               // 1
         "machine:\n"                                                 // 2
         "  name: m\n"                                                // 3
         "  io: {driver: loopback}\n"                                 // 4
         "tasks:\n"                                                   // 5
         "  - {name: fast, interval: 1ms, programs: [p]}\n"           // 6
         "programs:\n"                                                // 7
         "  - name: p\n"                                              // 8
         "    blocks:\n"                                              // 9
         "      - {name: a, type: LowPass, params: {tau: 10ms}}\n" +  // 10
         program_tail;
}

std::vector<Diagnostic> errors_of(const std::string& path) {
  try {
    parse_config_file(path);
  } catch (const ConfigError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << path << " was accepted";
  return {};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ConfigInclude, AFragmentsBlocksAndWiresAreAppendedWithTheirOwnLocations) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "frags");
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    wires:\n"                    // 11
                               "      a.in: 1.0\n"               // 12
                               "    include: frags/b.yaml\n"));  // 13
  // Relative to the fragment's own directory: frags/c.yaml.
  write_file(dir.file("frags/b.yaml"),
             "blocks:\n  - {name: b, type: LowPass, params: {tau: 20ms}}\n"
             "wires:\n  b.in: a.out\ninclude: [c.yaml]\n");
  write_file(dir.file("frags/c.yaml"),
             "blocks:\n  - {name: c, type: LowPass, params: {tau: 30ms}}\nwires:\n  c.in: b.out\n");
  const Config cfg = parse_config_file(main);
  ASSERT_EQ(cfg.programs.size(), 1u);
  const ProgramSpec& p = cfg.programs[0];
  ASSERT_EQ(p.blocks.size(), 3u);
  EXPECT_EQ(p.blocks[0].name, "a");  // the program's own first, then in include order
  EXPECT_EQ(p.blocks[1].name, "b");
  EXPECT_EQ(p.blocks[2].name, "c");
  ASSERT_EQ(p.wires.size(), 3u);
  EXPECT_EQ(p.wires[0].dest_loc.file, main);
  const std::string b = (dir.path() / "frags/b.yaml").string();
  const std::string c = (dir.path() / "frags/c.yaml").string();
  EXPECT_EQ(p.wires[1].dest_loc.file, b);
  EXPECT_EQ(p.wires[1].dest_loc.line, 4);
  EXPECT_EQ(p.wires[1].dest_loc.col, 3);
  EXPECT_EQ(p.blocks[2].name_loc.file, c);
  ASSERT_EQ(cfg.includes.size(), 2u);
  EXPECT_EQ(cfg.includes[0].note, "included from " + main + ":13:14");
  EXPECT_EQ(cfg.includes[1].note, "included from " + b + ":5:11, included from " + main + ":13:14");

  // And it builds and runs: c follows b follows a, wired across the three files.
  BlockRegistry blocks;
  blocks::register_builtin_blocks(blocks);
  DriverRegistry drivers;
  register_runtime_drivers(drivers);
  EXPECT_NO_THROW(Runtime::build(cfg, blocks, drivers));
}

TEST(ConfigInclude, AnErrorInAFragmentIsLocatedThereAndNamesTheIncludingFile) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: f.yaml\n"));
  write_file(dir.file("f.yaml"), "# a fragment\nwires:\n  a.in: [1, 2]\n");
  const std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.file, dir.file("f.yaml"));
  EXPECT_EQ(d[0].loc.line, 3);
  EXPECT_EQ(d[0].loc.col, 9);
  EXPECT_TRUE(has(d[0].str(), "(included from " + main + ":11:14)")) << d[0].str();
}

TEST(ConfigInclude, AWiringErrorTheBuilderFindsInAFragmentNamesTheIncludingFileToo) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: f.yaml\n"));
  write_file(dir.file("f.yaml"), "wires:\n  a.no_such_pin: 1.0\n");
  BlockRegistry blocks;
  blocks::register_builtin_blocks(blocks);
  DriverRegistry drivers;
  register_runtime_drivers(drivers);
  try {
    Runtime::build(parse_config_file(main), blocks, drivers);
    ADD_FAILURE() << "an unknown pin was accepted";
  } catch (const ConfigError& e) {
    const Diagnostic& d = e.diagnostics().front();
    EXPECT_EQ(d.loc.file, dir.file("f.yaml"));
    EXPECT_EQ(d.loc.line, 2);
    EXPECT_TRUE(has(d.message, "no_such_pin")) << d.str();
    EXPECT_TRUE(has(d.message, "(included from " + main + ":11:14)")) << d.str();
  }
}

TEST(ConfigInclude, AMissingFragmentIsAnErrorAtTheInclude) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: [nowhere.yaml]\n"));
  const std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.file, main);
  EXPECT_EQ(d[0].loc.line, 11);
  EXPECT_EQ(d[0].loc.col, 15);
  EXPECT_TRUE(has(d[0].message, "cannot include '" + dir.file("nowhere.yaml") + "'")) << d[0].str();
  // A directory is no fragment either.
  std::filesystem::create_directories(dir.path() / "sub");
  write_file(main, config_with("    include: sub\n"));
  EXPECT_TRUE(has(errors_of(main).at(0).message, "not a regular file")) << errors_of(main)[0].str();
}

TEST(ConfigInclude, ACycleIsRefusedWhereItCloses) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: f.yaml\n"));
  write_file(dir.file("f.yaml"), "include: g.yaml\n");
  write_file(dir.file("g.yaml"), "include: ./f.yaml\n");  // another spelling, the same file
  const std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.file, dir.file("g.yaml"));
  EXPECT_EQ(d[0].loc.line, 1);
  EXPECT_TRUE(has(d[0].message, "include cycle: " + dir.file("f.yaml") + " -> " +
                                    dir.file("g.yaml") + " -> " + dir.file("f.yaml")))
      << d[0].str();
  EXPECT_TRUE(has(d[0].message, "included from " + dir.file("f.yaml") + ":1:10, included from " +
                                    main + ":11:14"))
      << d[0].str();
  // The config including itself.
  write_file(main, config_with("    include: m.yaml\n"));
  EXPECT_TRUE(has(errors_of(main).at(0).message, "include cycle")) << errors_of(main)[0].str();
}

TEST(ConfigInclude, NestingDeeperThanEightIsRefused) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: f1.yaml\n"));
  for (int i = 1; i <= 9; ++i) {
    write_file(dir.file("f" + std::to_string(i) + ".yaml"),
               "include: f" + std::to_string(i + 1) + ".yaml\n");
  }
  write_file(dir.file("f10.yaml"), "wires: {a.in: 1}\n");
  std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.file, dir.file("f8.yaml"));  // f1..f8 read: eight deep
  EXPECT_TRUE(has(d[0].message, "nest more than 8 deep")) << d[0].str();
  // Eight deep is allowed.
  write_file(dir.file("f8.yaml"), "wires: {a.in: 1}\n");
  EXPECT_NO_THROW(parse_config_file(main));
}

TEST(ConfigInclude, AWireOrBlockDefinedTwiceIsAnErrorNamingBothPlaces) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    wires: {a.in: 1.0}\n"  // 11
                               "    include: [f.yaml, g.yaml]\n"));
  write_file(dir.file("f.yaml"), "blocks:\n  - {name: b, type: LowPass}\nwires:\n  a.in: 2.0\n");
  write_file(dir.file("g.yaml"),
             "blocks:\n  - {name: a, type: LowPass}\n  - {name: b, type: Gain}\n");
  const std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 3u);
  // In file order: f.yaml (read first), then g.yaml.
  EXPECT_EQ(d[0].loc.file, dir.file("f.yaml"));
  EXPECT_EQ(d[0].loc.line, 4);
  EXPECT_TRUE(has(d[0].message, "input 'a.in' is wired twice (first at " + main + ":11:13)"))
      << d[0].str();
  EXPECT_EQ(d[1].loc.file, dir.file("g.yaml"));
  EXPECT_EQ(d[1].loc.line, 2);
  EXPECT_TRUE(
      has(d[1].message, "duplicate block name 'a' in program 'p' (first at " + main + ":10:16)"))
      << d[1].str();
  EXPECT_EQ(d[2].loc.line, 3);
  EXPECT_TRUE(has(d[2].message, "duplicate block name 'b' in program 'p' (first at " +
                                    dir.file("f.yaml") + ":2:12)"))
      << d[2].str();
  for (const Diagnostic& e : d) {
    EXPECT_TRUE(has(e.message, "(included from " + main + ":12:")) << e.str();
  }
}

TEST(ConfigInclude, AFragmentHoldsOnlyBlocksWiresAndIncludes) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: f.yaml\n"));
  write_file(dir.file("f.yaml"), "wires: {}\ntasks: []\n");
  std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.line, 2);
  EXPECT_TRUE(has(d[0].message, "tasks")) << d[0].str();
  write_file(dir.file("f.yaml"), "# nothing\n");
  EXPECT_TRUE(has(errors_of(main).at(0).message, "the fragment is empty"));
  write_file(dir.file("f.yaml"), "- a\n");
  EXPECT_TRUE(has(errors_of(main).at(0).message, "a fragment must be a map"));
  write_file(dir.file("f.yaml"), "wires: {a.in: 1\n");  // YAML syntax, located in the fragment
  d = errors_of(main);
  EXPECT_EQ(d.at(0).loc.file, dir.file("f.yaml"));
  EXPECT_TRUE(has(d[0].message, "YAML syntax error")) << d[0].str();
  write_file(main, config_with("    include: []\n"));
  EXPECT_TRUE(has(errors_of(main).at(0).message, "must name at least one fragment"));
}

TEST(ConfigInclude, TheConfigAndItsFragmentsKeepTheConfigSizeLimitTogether) {
  TempDir dir;
  const std::string main = dir.file("m.yaml");
  write_file(main, config_with("    include: [f.yaml, g.yaml]\n"));
  const std::string comment = "#" + std::string((std::size_t{3} << 20) - 2, 'x') + "\n";
  write_file(dir.file("f.yaml"), comment + "wires: {a.in: 1}\n");  // 3 MiB: fine alone
  write_file(dir.file("g.yaml"), comment + "blocks: []\n");        // 6 MiB in all: too much
  const std::vector<Diagnostic> d = errors_of(main);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].loc.file, main);
  EXPECT_EQ(d[0].loc.col, 23);
  EXPECT_TRUE(has(d[0].message, "larger than 4 MiB together")) << d[0].str();
}

// The shipped drill machines: one job wiring (config/machines/fragments/drill-job-wiring.yaml),
// and each machine's own wires beside it; drill-fuzzy-sim has the manual functions' wires.
TEST(ConfigInclude, TheShippedDrillMachinesShareOneJobWiring) {
  const std::string dir = std::string(EDM_SOURCE_DIR) + "/config/machines/";
  const auto cnc_wires = [&](const std::string& machine) {
    const Config cfg = parse_config_file(dir + machine + ".yaml");
    std::set<std::string> fragment, own;
    for (const ProgramSpec& p : cfg.programs) {
      if (p.name != "cnc") continue;
      for (const WireSpec& w : p.wires) {
        const bool shared =
            w.dest_loc.file.find("fragments/drill-job-wiring.yaml") != std::string::npos;
        (shared ? fragment : own).insert(w.dest + " <- " + w.source);
      }
    }
    return std::pair{fragment, own};
  };
  const auto [sim, sim_own] = cnc_wires("drill-sim");
  EXPECT_GE(sim.size(), 30u);
  EXPECT_TRUE(sim_own.empty());
  const auto [modbus, modbus_own] = cnc_wires("drill-modbus-sim");
  EXPECT_EQ(modbus, sim);
  EXPECT_EQ(modbus_own, (std::set<std::string>{"io.flush_pump <- job.flushing_on"}));
  const auto [fuzzy, fuzzy_own] = cnc_wires("drill-fuzzy-sim");
  EXPECT_EQ(fuzzy, sim);
  for (const std::string& w : fuzzy_own) {  // its servo chain only: no job↔io wire of its own
    EXPECT_FALSE(w.rfind("io.", 0) == 0 || w.find("<- job.") != std::string::npos) << w;
  }
  const auto manual = std::count_if(fuzzy.begin(), fuzzy.end(), [](const std::string& w) {
    return w.find("job.manual.") != std::string::npos;
  });
  EXPECT_EQ(manual, 11);
}

}  // namespace
}  // namespace edm::rt
