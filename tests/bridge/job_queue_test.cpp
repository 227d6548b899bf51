// The job queue (issue 33, "a job queue"; hmi/include/edm/hmi/job_queue.hpp) on drill-sim with
// the bridge: a program whose third hole the electrode cannot finish runs its first two, the
// machine stops above the third and the queue asks for a change; the electrode is changed and
// measured on the work (no touch-off of the frame), the program goes on from that hole, and the
// queue goes on with the next program. Every hole ends within 10 µm of its depth (the
// simulator's true depth), the job log has every job with its electrode, and the table the holes.
#include "edm/hmi/job_queue.hpp"

#include <gtest/gtest.h>

#include <map>

#include "bridge_fixture.hpp"
#include "programs/sim_machine.hpp"
#include "support/runtime_thread.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;

// Three 4 mm holes 10 mm apart; E1 positions over each at Z0.5 (work coordinates, G54).
constexpr const char* kThreeHoles = R"(%
G17 G21 G90
G00 Z5
G00 X-20 Y10
M03 M08
F60
G00 Z0.5
E1
G01 Z-4
E0
G00 Z2
G00 X-10 Y10
G00 Z0.5
E1
G01 Z-4
E0
G00 Z2
G00 X0 Y10
G00 Z0.5
E1
G01 Z-4
E0
G00 Z5
M05 M09
M30
%
)";

constexpr const char* kOneHole = R"(%
G17 G21 G90
G00 Z5
G00 X10 Y10
M03 M08
F60
G00 Z0.5
E1
G01 Z-4
E0
G00 Z5
M30
%
)";

TEST(JobQueue, StopsBeforeTheHoleTheElectrodeCannotFinishAndGoesOnAfterAMeasuredChange) {
  std::string text =
      edm::test::read_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  // 300 mm of electrode, of which the holder leaves 292 mm unusable: 8 mm, about two 4 mm holes
  // (eq. 10 plans ~3.3 mm a hole at E1).
  edm::test::replace_once(text, "margin_mm: 5}", "margin_mm: 292}");
  auto rt = edm::test::build_sim_machine(
      rt::parse_config_text(text, std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml"));
  auto server = start_server(*rt);
  edm::test::RuntimeThread runner;
  runner.start(*rt, edm::test::paced_virtual_clock(10.0));
  runner.wait_until_powered_on();
  Client queue_client, op;
  ASSERT_EQ(queue_client.connect(client_options(*server)), Role::kOperator);
  ASSERT_EQ(op.connect(client_options(*server)), Role::kOperator);
  ASSERT_TRUE(op.request("offset.set", {{"frame", "G54"}, {"z", 0.0}}));  // with 300 mm
  ASSERT_TRUE(op.request("electrode.change", {{"electrode", "E1"},
                                              {"kind", "tube"},
                                              {"size_mm", 1.0},
                                              {"material", "copper"},
                                              {"new_length_mm", 300.0}}));
  ASSERT_TRUE(op.request("electrode.set", {{"length_mm", 300.0}}));

  std::map<int, double> depth;  // 1000 × job + drilling line → its hole's true depth at its end
  int changes = 0, job = 0;
  std::atomic<bool> stop{false};
  hmi::QueueCallbacks cb;
  cb.electrode_poll = 20ms;
  cb.run.progress = [&](const hmi::ProgressView& v) {
    if (v.kind == machining::MotionKind::kDrill) {
      depth[1000 * job + v.line] = rt->variables().read("io.depth_mm").value_or(-1.0);
    }
  };
  cb.job_done = [&](const hmi::QueueJob&) { ++job; };
  cb.note = [&](const std::string& n) {
    if (n.find("stopped before the hole of line 21") == std::string::npos) return;
    ++changes;
    // The operator changes the electrode (a new one, 300 mm) and measures it on the work.
    ASSERT_TRUE(rt->variables().write("io.electrode_length_mm", 300.0, true));
    ASSERT_TRUE(op.request("electrode.change", {{"electrode", "E2"},
                                                {"kind", "tube"},
                                                {"size_mm", 1.0},
                                                {"material", "copper"},
                                                {"new_length_mm", 300.0}}));
    // The queue raised Z to 1 mm below its top (20 mm) for the change: down 10 mm, within the
    // touch's 20 mm.
    EXPECT_NEAR(rt->variables().read("io.z_mm").value_or(0.0), 19.0, 0.05);
    const Reply j = op.request("jog", {{"axis", "Z"}, {"distance", -10.0}});
    ASSERT_TRUE(j) << j.body;
    while (op.request("manual.status").body.value("seen_seq", 0U) < j.body["seq"].get<unsigned>() ||
           op.request("manual.status").body.value("busy", true)) {
      std::this_thread::sleep_for(20ms);  // polling an observable state, as edmhmi does
    }
    const Reply m = op.request("electrode.measure", {{"reference", "work"}});
    ASSERT_TRUE(m) << m.body;
    for (;;) {  // the queue waits for a measured change: a failed one ends the test
      const Json last = op.request("electrode.get").body["last_measure"];
      if (last.is_object() && last["seq"] == m.body["seq"]) {
        EXPECT_TRUE(last["ok"].get<bool>()) << last;
        if (!last["ok"].get<bool>()) stop = true;
        break;
      }
      std::this_thread::sleep_for(20ms);  // polling an observable state, as edmhmi does
    }
  };
  const std::vector<hmi::QueueItem> items{{"three.nc", kThreeHoles, 1}, {"one.nc", kOneHole, 1}};
  const hmi::QueueResult r = hmi::run_queue(queue_client, items, cb, stop);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(changes, 1);
  ASSERT_EQ(r.jobs.size(), 3u) << "three.nc up to line 21, from line 21, one.nc";
  EXPECT_EQ(r.jobs[0].before_line, 21);
  EXPECT_EQ(r.jobs[1].from_line, 21);
  ASSERT_EQ(depth.size(), 4u);
  for (const auto& [key, d] : depth) {
    EXPECT_NEAR(d, 4.0, 0.010) << "job " << key / 1000 << " line " << key % 1000;
    std::printf("job %d line %d: hole depth %.4f mm\n", key / 1000, key % 1000, d);
  }
  EXPECT_EQ(depth.count(1021), 1u) << "the third hole, after the change";

  Json jobs;
  for (;;) {  // the last job is logged one progress tick after its end
    jobs = op.request("jobs.get").body["jobs"];
    if (jobs.size() >= 3) break;
    std::this_thread::sleep_for(20ms);  // polling an observable state, as edmhmi does
  }
  const Json e = op.request("electrode.get").body;
  EXPECT_EQ(e["current"], "E2");
  EXPECT_NEAR(e["length_mm"].get<double>(), 300.0 - 2 * 3.3, 1.0) << e;
  std::vector<std::string> used;
  std::vector<std::int64_t> holes;
  for (const Json& j : jobs) {
    if (j["slot"] != "main") continue;
    used.push_back(j["electrode"].get<std::string>());
    holes.push_back(j["holes"].get<std::int64_t>());
    // The figures of each job, also of one whose successor started within a progress tick of
    // its end (taken at that cycle.start, before the new job resets them).
    EXPECT_GT(j["time_s"].get<double>(), 1.0) << j;
    EXPECT_NEAR(j["depth_mm"].get<double>(), 4.0, 0.05) << j;
    EXPECT_GT(j["wear_mm"].get<double>(), 0.5) << j;
  }
  EXPECT_EQ(used, (std::vector<std::string>{"E1", "E2", "E2"})) << jobs;
  EXPECT_EQ(holes, (std::vector<std::int64_t>{2, 1, 1})) << jobs;
  for (const Json& t : e["table"]) {
    EXPECT_EQ(t["holes"], 2) << "E1 drilled two holes, E2 two: " << t;
  }
  runner.stop();
  server->stop();
}

}  // namespace
}  // namespace edm::bridge::test
