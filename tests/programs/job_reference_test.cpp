// Behaviour references of issue 18 for the job sequencer: drill-sim and drill-fuzzy-sim only idle
// under `edmplc --run-for` (EdmJob waits for a part program), so tests/reference/record.sh cannot
// see EdmJob at work. Here the shipped example part program runs through the HMI's interpreter on
// those machines, on the virtual clock with seed 1, for 10 s (rapid, E1, drilling with the gap
// loop), and the FNV-1a 64 of the trace CSV must match tests/reference/jobs.fnv64.
// Re-record (only for an intended change of behaviour): tests/reference/record.sh, which runs this
// test with EDM_RECORD_REFERENCES=1.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "sim_machine.hpp"
#include "support/temp_dir.hpp"

namespace edm {
namespace {

const std::string kSource = EDM_SOURCE_DIR;
const std::string kSums = kSource + "/tests/reference/jobs.fnv64";

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string fnv1a64_hex(const std::string& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::map<std::string, std::string> read_sums() {
  std::map<std::string, std::string> sums;
  std::istringstream in(read_file(kSums));
  std::string hash, name;
  while (in >> hash >> name) {
    sums[name] = hash;
  }
  return sums;
}

// The trace of config/machines/<machine>.yaml running examples/parts/drill-then-finish.nc.
std::string job_trace(const std::string& machine) {
  const std::string cfg = kSource + "/config/machines/" + machine + ".yaml";
  const std::string text = read_file(kSource + "/examples/parts/drill-then-finish.nc");
  hmi::GcodeOptions o;
  o.start_mm = {0, 0, 0.1};  // where the simulated electrode starts
  const auto g =
      hmi::interpret_gcode(text, "drill-then-finish.nc", machining::read_machine_tables(cfg), o);
  EXPECT_TRUE(g.ok());
  rt::BuildOptions bo;
  bo.seed = 1;
  bo.load_retain = false;
  auto r = test::build_sim_machine(rt::parse_config_file(cfg), bo);
  EXPECT_EQ(r->job().load(g.blocks), rt::LoadResult::kOk);
  r->machine().command(rt::MachineCommand::kPowerOn);
  EXPECT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  const test::TempDir dir("edm-job-reference");
  rt::RunOptions ro;
  ro.clock = rt::ClockKind::kVirtual;
  ro.run_for = std::chrono::seconds(10);
  ro.trace_out = dir.file("trace.csv");
  r->run(ro);
  EXPECT_GT(r->variables().read("io.depth_mm").value_or(0.0), 0.1) << machine << ": no drilling";
  return read_file(ro.trace_out);
}

class JobReference : public ::testing::TestWithParam<const char*> {};

TEST_P(JobReference, TraceOfTheExamplePartProgramIsUnchanged) {
  const std::string machine = GetParam();
  const std::string csv = job_trace(machine);
  ASSERT_GT(csv.size(), 1000u);
  const std::string got = fnv1a64_hex(csv);
  EXPECT_EQ(got, fnv1a64_hex(job_trace(machine))) << "not deterministic";
  auto sums = read_sums();
  if (std::getenv("EDM_RECORD_REFERENCES") != nullptr) {
    sums[machine] = got;
    std::ofstream out(kSums, std::ios::trunc);
    for (const auto& [name, hash] : sums) {
      out << hash << "  " << name << "\n";
    }
    return;
  }
  ASSERT_TRUE(sums.count(machine) != 0) << "no reference for " << machine << " in " << kSums
                                        << ": record it with tests/reference/record.sh";
  EXPECT_EQ(got, sums[machine])
      << machine << " running examples/parts/drill-then-finish.nc: the trace changed. If the "
      << "change of behaviour is intended, re-record with tests/reference/record.sh and say in "
      << "the commit which trace changed and why";
}

INSTANTIATE_TEST_SUITE_P(Shipped, JobReference, ::testing::Values("drill-sim", "drill-fuzzy-sim"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           std::string n = p.param;
                           for (char& c : n) {
                             if (c == '-') c = '_';
                           }
                           return n;
                         });

}  // namespace
}  // namespace edm
