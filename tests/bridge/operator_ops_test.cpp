// The operator functions' ops (issue 21) on an in-process drill machine (the simulator, virtual
// clock paced 10x) with a bridge: roles, precise refusals of bad requests and of requests in the
// wrong state, a jog and a work offset through the protocol, the reference requirement and the
// offset generation at cycle.start, and MDI that never replaces the loaded part program.
#include <gtest/gtest.h>

#include <cstdint>

#include "bridge_fixture.hpp"
#include "edm/machining/motion_block.hpp"
#include "programs/sim_machine.hpp"
#include "support/runtime_thread.hpp"

namespace edm::bridge::test {
namespace {

using machining::MotionBlock;
using machining::MotionKind;
using namespace std::chrono_literals;

constexpr const char* kOp = "op-secret-0123456789";
constexpr const char* kViewer = "viewer-secret-0123456789";

class OperatorOps : public ::testing::Test {
 protected:
  void start(const std::string& manual_params = "") {
    std::string text =
        edm::test::read_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
    if (!manual_params.empty()) {
      edm::test::replace_once(text, "manual: {}", "manual: {" + manual_params + "}");
    }
    rt_ = edm::test::build_sim_machine(rt::parse_config_text(
        text, std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml"));
    ServerOptions o;
    o.token_file = dir_.file("op.token");
    o.viewer_token_file = dir_.file("viewer.token");
    write_token(o.token_file, kOp, 0600);
    write_token(o.viewer_token_file, kViewer, 0600);
    server_ = start_server(*rt_, o);
    runner_.start(*rt_, edm::test::paced_virtual_clock(10.0));
    runner_.wait_until_powered_on();
    ASSERT_EQ(op_.connect(opts(kOp)), Role::kOperator);
    ASSERT_EQ(viewer_.connect(opts(kViewer)), Role::kViewer);
  }
  void TearDown() override {
    runner_.stop();
    if (server_) server_->stop();
  }
  ClientOptions opts(const std::string& token) const { return client_options(*server_, token); }
  /// Polls manual.status until the request `seq` is done; returns the final status.
  Json wait_manual(std::uint64_t seq) {
    Json st;
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    while (std::chrono::steady_clock::now() < deadline) {
      const Reply r = viewer_.request("manual.status");
      EXPECT_TRUE(r.ok) << r.body;
      st = r.body;
      if (st.value("seen_seq", 0U) >= seq && !st.value("busy", true)) return st;
      std::this_thread::sleep_for(20ms);  // polling an observable status, as edmhmi does
    }
    ADD_FAILURE() << "manual request " << seq << " not done: " << st;
    return st;
  }
  double var(const char* name) { return rt_->variables().read(name).value_or(1e9); }
  void wait_for_busy() {
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (!rt_->manual().status().busy) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the jog never started";
      std::this_thread::yield();
    }
  }

  edm::test::TempDir dir_{"edm-operator-ops"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  edm::test::RuntimeThread runner_;
  Client op_, viewer_;
};

TEST_F(OperatorOps, ViewersMayWatchButNeverMove) {
  start();
  for (const auto& [op, params] :
       std::vector<std::pair<const char*, Json>>{{"home", Json::object()},
                                                 {"jog", {{"axis", "X"}, {"distance", 1.0}}},
                                                 {"jog.stop", Json::object()},
                                                 {"touch", {{"target", "z"}}},
                                                 {"offset.set", {{"frame", "G54"}, {"x", 1.0}}}}) {
    expect_error(viewer_.request(op, params), ErrorCode::kForbidden);
  }
  EXPECT_TRUE(viewer_.request("manual.status"));
  EXPECT_TRUE(viewer_.request("offset.get"));
  EXPECT_EQ(rt_->manual().status().seen_seq, 0U) << "nothing reached the runtime";
  const Reply info = viewer_.request("machine.info");
  ASSERT_TRUE(info);
  EXPECT_TRUE(info.body["manual"]["available"].get<bool>());
  EXPECT_TRUE(info.body["manual"]["home"].get<bool>());
  EXPECT_TRUE(info.body["manual"]["touch"].get<bool>());
  EXPECT_NE(std::find(info.body["ops"].begin(), info.body["ops"].end(), Json("touch")),
            info.body["ops"].end());
}

TEST_F(OperatorOps, BadRequestsAreRefusedPrecisely) {
  start();
  const std::vector<std::pair<const char*, Json>> bad = {
      {"jog", Json::object()},
      {"jog", {{"axis", "W"}, {"distance", 1.0}}},
      {"jog", {{"axis", 5}, {"distance", 1.0}}},
      {"jog", {{"axis", "X"}}},
      {"jog", {{"axis", "X"}, {"distance", 1.0}, {"velocity", 1.0}}},
      {"jog", {{"axis", "X"}, {"distance", 10.5}}},
      {"jog", {{"axis", "X"}, {"distance", 0.0001}}},
      {"jog", {{"axis", "X"}, {"distance", "1"}}},
      {"jog", {{"axis", "X"}, {"velocity", 50.0}}},
      {"jog", {{"axis", "X"}, {"velocity", 1e308}}},
      {"touch", Json::object()},
      {"touch", {{"target", "q"}}},
      {"touch", {{"target", 3}}},
      {"home", {{"axes", "XX"}}},
      {"home", {{"axes", "W"}}},
      {"home", {{"axes", ""}}},
      {"home", {{"axes", 5}}},
      {"offset.set", {{"frame", "G60"}, {"x", 1.0}}},
      {"offset.set", {{"frame", "G5"}, {"x", 1.0}}},
      {"offset.set", {{"frame", "G54"}}},
      {"offset.set", {{"frame", "G54"}, {"x", "abc"}}},
      {"offset.set", {{"frame", "G54"}, {"x", 1e9}}},
      {"offset.set", {{"frame", "G55"}, {"y", 5000.0}}},  // drill-sim: Y −100 .. 100
      {"offset.set", {{"frame", "G55"}, {"z", -60.001}}},
      {"cycle.start", {{"slot", "other"}}},
      {"cycle.start", {{"dry_run", "yes"}}},
      {"program.begin", {{"blocks", 1}, {"slot", "x"}}},
      {"program.begin", {{"blocks", 1}, {"offsets_generation", -1}}},
  };
  for (const auto& [op, params] : bad) {
    const Reply r = op_.request(op, params);
    EXPECT_FALSE(r.ok) << op << " " << params;
    EXPECT_EQ(r.code, ErrorCode::kBadRequest) << op << " " << params << " → " << r.body;
  }
  EXPECT_EQ(rt_->manual().status().seen_seq, 0U) << "nothing reached the runtime";
  EXPECT_EQ(rt_->work_offsets().generation(), 0U);
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady);
}

TEST_F(OperatorOps, ManualMotionOnlyWhenReadyAndIdle) {
  start("deadman: 60s");  // the slow jog below must outlast the requests that test it
  ASSERT_TRUE(op_.request("estop"));
  for (const auto& [op, params] :
       std::vector<std::pair<const char*, Json>>{{"home", Json::object()},
                                                 {"jog", {{"axis", "X"}, {"distance", 1.0}}},
                                                 {"touch", {{"target", "z"}}}}) {
    expect_error(op_.request(op, params), ErrorCode::kInvalidState);
  }
  EXPECT_TRUE(op_.request("jog.stop")) << "a stop is always accepted";
  ASSERT_TRUE(op_.request("reset"));
  // A jog through the protocol moves the axis by exactly its distance.
  const double x0 = var("io.x_mm");
  const Reply r = op_.request("jog", {{"axis", "X"}, {"distance", -1.25}});
  ASSERT_TRUE(r) << r.body;
  const Json st = wait_manual(r.body["seq"].get<std::uint64_t>());
  EXPECT_TRUE(st["result"]["ok"].get<bool>()) << st;
  EXPECT_NEAR(var("io.x_mm") - x0, -1.25, 0.0015);
  // While one manual operation runs, another (not a continuous jog) is invalid_state.
  const Reply slow = op_.request("jog", {{"axis", "Y"}, {"velocity", 0.5}});
  ASSERT_TRUE(slow);
  wait_for_busy();
  expect_error(op_.request("home", {{"axes", "Z"}}), ErrorCode::kInvalidState);
  expect_error(op_.request("cycle.start"), ErrorCode::kInvalidState);
  const Reply stop = op_.request("jog.stop");
  ASSERT_TRUE(stop);
  const Json stopped = wait_manual(stop.body["seq"].get<std::uint64_t>());
  EXPECT_FALSE(stopped["busy"].get<bool>());
  EXPECT_EQ(stopped["result"]["error"], "stopped by the operator");
}

TEST_F(OperatorOps, AWorkOriginAtTheSoftLimitsIsKept) {
  start();
  const Reply r =
      op_.request("offset.set", {{"frame", "G56"}, {"x", 100.0}, {"y", -100.0}, {"z", -60.0}});
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(rt_->work_offsets().get(2).y, -100.0);
}

TEST_F(OperatorOps, WorkOffsetsAreSetReadAndRefusedDuringAJob) {
  start();
  // An origin the machine cannot reach is refused with the limits; one at a limit is kept.
  Reply far = op_.request("offset.set", {{"frame", "G55"}, {"y", 5000.0}});
  EXPECT_EQ(far.code, ErrorCode::kBadRequest);
  EXPECT_NE(far.message.find("'y' 5000 mm is outside the Y soft limits (-100 .. 100 mm)"),
            std::string::npos)
      << far.message;
  EXPECT_EQ(rt_->work_offsets().generation(), 0U) << "nothing changed";
  Reply r = op_.request("offset.set", {{"frame", "G55"}, {"x", 12.5}, {"z", -7.25}});
  ASSERT_TRUE(r) << r.body;
  EXPECT_EQ(r.body["frame"], "G55");
  EXPECT_EQ(r.body["generation"], 1);
  r = viewer_.request("offset.get");
  ASSERT_TRUE(r);
  EXPECT_EQ(r.body["frames"]["G55"]["x"], 12.5);
  EXPECT_EQ(r.body["frames"]["G55"]["y"], 0.0);
  EXPECT_EQ(r.body["frames"]["G55"]["z"], -7.25);
  EXPECT_EQ(r.body["frames"]["G54"]["x"], 0.0);
  // A program interpreted with generation 1, then the offsets change: the start is refused.
  MotionBlock dwell = dwell_block(0.05, 1);
  const MotionBlock end = end_block(2);
  const std::vector<MotionBlock> prog{dwell, end};
  UploadOptions uo;
  uo.offsets_generation = 1;
  ASSERT_TRUE(op_.upload_program(prog, uo));
  ASSERT_TRUE(op_.request("offset.set", {{"frame", "G54"}, {"y", 3.0}}));
  const Reply refused = op_.request("cycle.start");
  expect_error(refused, ErrorCode::kInvalidState);
  EXPECT_NE(refused.body.dump().find("work offsets changed"), std::string::npos);
  uo.offsets_generation = 2;
  ASSERT_TRUE(op_.upload_program(prog, uo));
  // A long dwell: offsets are refused while it runs.
  dwell.dwell_s = 30.0;
  const std::vector<MotionBlock> long_prog{dwell, end};
  ASSERT_TRUE(op_.upload_program(long_prog, uo));
  ASSERT_TRUE(op_.request("cycle.start"));
  expect_error(op_.request("offset.set", {{"frame", "G54"}, {"x", 1.0}}), ErrorCode::kInvalidState);
  expect_error(op_.request("jog", {{"axis", "X"}, {"distance", 1.0}}), ErrorCode::kInvalidState);
  ASSERT_TRUE(op_.request("cycle.stop"));
  EXPECT_EQ(rt_->work_offsets().get(0).x, 0.0);
}

TEST_F(OperatorOps, ProgramsWaitForTheReferenceWhenRequired) {
  start("referenced_at_start: false, reference_required: true");
  const std::vector<MotionBlock> prog{end_block(1)};
  ASSERT_TRUE(op_.upload_program(prog));
  const Reply r = op_.request("cycle.start");
  expect_error(r, ErrorCode::kInvalidState);
  EXPECT_NE(r.body.dump().find("not referenced"), std::string::npos) << r.body;
  const Reply h = op_.request("home", {{"axes", "ZXY"}});
  ASSERT_TRUE(h) << h.body;
  EXPECT_EQ(h.body["axes"], "XYZ");
  const Json st = wait_manual(h.body["seq"].get<std::uint64_t>());
  EXPECT_TRUE(st["result"]["ok"].get<bool>()) << st;
  EXPECT_TRUE(st["referenced"]["X"].get<bool>());
  EXPECT_TRUE(st["may_run_programs"].get<bool>());
  EXPECT_TRUE(op_.request("cycle.start"));
}

TEST_F(OperatorOps, MdiRunsBesideTheLoadedProgramWithoutReplacingIt) {
  start();
  const MotionBlock dwell = dwell_block(0.01, 7);
  const MotionBlock end = end_block(8);
  const std::vector<MotionBlock> main_prog{dwell, dwell, end};
  ASSERT_TRUE(op_.upload_program(main_prog));
  expect_error(op_.request("cycle.start", {{"slot", "mdi"}}), ErrorCode::kInvalidState);
  MotionBlock move;
  move.kind = MotionKind::kRapid;
  move.line = 1;
  move.target = {var("io.x_mm") + 2.0, var("io.y_mm"), var("io.z_mm")};
  UploadOptions uo;
  uo.slot = "mdi";
  const std::vector<MotionBlock> mdi{move, end};
  const double x0 = var("io.x_mm");
  ASSERT_TRUE(op_.upload_program(mdi, uo));
  EXPECT_EQ(rt_->job().loaded_blocks(), 3U) << "the part program is kept";
  ASSERT_TRUE(op_.request("cycle.start", {{"slot", "mdi"}}));
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (rt_->job().progress().jobs_started == 0 || rt_->job().active()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(rt_->job().progress().outcome, rt::JobOutcome::kFinished);
  EXPECT_EQ(rt_->job().progress().slot, rt::JobSlot::kMdi);
  // Read right after the job's end: the axis may still settle (in position = 2 µm for 5 cycles,
  // then the mechanics' overshoot); this test is about the slot, not the accuracy.
  EXPECT_NEAR(var("io.x_mm") - x0, 2.0, 0.05);
  EXPECT_EQ(rt_->job().loaded_blocks(), 3U);
  // The part program still runs as loaded.
  ASSERT_TRUE(op_.request("cycle.start"));
  while (rt_->job().progress().jobs_started < 2 || rt_->job().active()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(rt_->job().progress().slot, rt::JobSlot::kMain);
  EXPECT_EQ(rt_->job().progress().block_count, 3U);
}

// A machine stops before a hole it cannot finish (issue 33): cycle.start compares the program's
// planned wear (eq. 9-11, hole by hole) with the electrode left less the supervisor's margin,
// and refuses naming the first hole the electrode would not finish. A dry run wears nothing.
TEST_F(OperatorOps, ACycleStartIsRefusedWhenTheElectrodeCannotFinishTheProgram) {
  start();
  MotionBlock e1;
  e1.kind = MotionKind::kCondition;
  e1.condition = 1;
  e1.line = 3;
  const double z = var("io.z_mm");
  std::vector<MotionBlock> prog{e1};
  for (const std::int32_t line : {4, 6}) {  // two 8 mm holes (the check is offline: one XY does)
    if (line == 6) {
      MotionBlock up;
      up.kind = MotionKind::kRapid;
      up.line = 5;
      up.target = {var("io.x_mm"), var("io.y_mm"), z};
      prog.push_back(up);
    }
    MotionBlock hole;
    hole.kind = MotionKind::kDrill;
    hole.line = line;
    hole.condition = 1;
    hole.target = {var("io.x_mm"), var("io.y_mm"), z - 8.0};
    hole.depth_mm = 8.0;
    hole.z_travel_mm = 8.0 * 1.6;
    hole.feed_mm_s = 1.0;
    prog.push_back(hole);
  }
  prog.push_back(end_block(7));
  ASSERT_TRUE(op_.upload_program(prog));
  const Json planned = op_.request("electrode.get").body;
  ASSERT_EQ(planned["length_mm"], 300.0);

  // 13 mm of electrode: 8 usable above the 5 mm margin; the first hole plans ~6.6 mm, both ~13.
  ASSERT_TRUE(op_.request("electrode.set", {{"length_mm", 13.0}}));
  const Reply r = op_.request("cycle.start");
  expect_error(r, ErrorCode::kInvalidState);
  EXPECT_NE(r.message.find("run out in the hole of line 6"), std::string::npos) << r.message;
  EXPECT_EQ(r.details["line"], 6) << r.details;
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady) << "nothing started";

  // A dry run never erodes: it may start (it ends within a few cycles: nothing to drill).
  const std::uint64_t before = rt_->job().progress().jobs_started;
  ASSERT_TRUE(op_.request("cycle.start", {{"dry_run", true}}));
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (rt_->job().active() || rt_->machine().state() != rt::MachineState::kReady) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(rt_->job().progress().jobs_started, before + 1) << "the dry run ran";
  // Enough electrode: the start is accepted.
  ASSERT_TRUE(op_.request("electrode.set", {{"length_mm", 40.0}}));
  EXPECT_TRUE(op_.request("cycle.start"));
  ASSERT_TRUE(op_.request("cycle.stop"));
}

// An electrode change (issue 33): the table takes a new electrode only with all its fields,
// refuses malformed ones precisely, puts it in the spindle with its new length, and a job (but a
// dry run) waits until it is measured.
TEST_F(OperatorOps, AnElectrodeChangeIsValidatedAndAJobWaitsForItsMeasurement) {
  start();
  const Json e2{{"electrode", "E2"},
                {"kind", "tube"},
                {"size_mm", 1.0},
                {"material", "copper"},
                {"new_length_mm", 250.0}};
  const auto with = [&](const char* key, Json v) {
    Json j = e2;
    if (v.is_null()) {
      j.erase(key);
    } else {
      j[key] = std::move(v);
    }
    return j;
  };
  for (const Json& bad :
       {with("electrode", nullptr), with("electrode", ""), with("electrode", "E 2"),
        with("electrode", std::string(33, 'a')), with("electrode", 7), with("kind", nullptr),
        with("kind", "square"), with("material", nullptr), with("material", std::string(33, 'c')),
        with("material", "cu\nw"), with("size_mm", nullptr), with("size_mm", 0.0),
        with("size_mm", "1"), with("new_length_mm", nullptr), with("new_length_mm", 2e4),
        with("new_length_mm", -1.0)}) {
    const Reply r = op_.request("electrode.change", bad);
    EXPECT_EQ(r.code, ErrorCode::kBadRequest) << bad << " → " << r.body;
  }
  expect_error(viewer_.request("electrode.change", e2), ErrorCode::kForbidden);
  EXPECT_EQ(rt_->electrode().length_mm(), 300.0) << "nothing changed";
  EXPECT_TRUE(op_.request("electrode.get").body["current"].is_null());

  const Reply c = op_.request("electrode.change", e2);
  ASSERT_TRUE(c) << c.body;
  EXPECT_EQ(c.body["current"], "E2");
  EXPECT_EQ(c.body["length_mm"], 250.0) << "the job compensates with its new length";
  EXPECT_FALSE(c.body["table"][0]["measured"].get<bool>());
  EXPECT_EQ(rt_->electrode().length_mm(), 250.0);
  // A known id may come back with none of its fields.
  ASSERT_TRUE(op_.request("electrode.change", {{"electrode", "E2"}}));

  MotionBlock e1;
  e1.kind = MotionKind::kCondition;
  e1.condition = 1;
  e1.line = 1;
  MotionBlock hole;
  hole.kind = MotionKind::kDrill;
  hole.line = 2;
  hole.condition = 1;
  hole.target = {var("io.x_mm"), var("io.y_mm"), var("io.z_mm") - 2.0};
  hole.depth_mm = 2.0;
  hole.z_travel_mm = 3.2;
  hole.feed_mm_s = 1.0;
  ASSERT_TRUE(op_.upload_program(std::vector<MotionBlock>{e1, hole, end_block(3)}));
  const Reply refused = op_.request("cycle.start");
  expect_error(refused, ErrorCode::kInvalidState);
  EXPECT_NE(refused.message.find("E2 was put in the spindle and not measured"), std::string::npos)
      << refused.message;
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady) << "nothing started";
  // A length measured off the machine counts as its measurement.
  ASSERT_TRUE(op_.request("electrode.set", {{"length_mm", 249.0}}));
  EXPECT_TRUE(op_.request("electrode.get").body["table"][0]["measured"].get<bool>());
  EXPECT_TRUE(op_.request("cycle.start"));
  // No change while a job runs.
  expect_error(op_.request("electrode.change", {{"electrode", "E2"}}), ErrorCode::kInvalidState);
  ASSERT_TRUE(op_.request("cycle.stop"));
}

// The tool setter (drill-sim: at X-45 Y-45, z_mm −300) measures the electrode's true length,
// whatever the control believed: the simulator's electrode is set to a length the control does
// not know, and the measurement finds it. A touch off the setter measures nothing.
TEST_F(OperatorOps, MeasuringOnTheToolSetterFindsTheElectrodesTrueLength) {
  start();
  const double z = var("io.z_mm") + 5.0;  // 5 mm above the work: within the touch's 20 mm
  const auto run_to = [&](double x, double y) {
    MotionBlock up;
    up.kind = MotionKind::kRapid;
    up.line = 1;
    up.target = {var("io.x_mm"), var("io.y_mm"), z};
    MotionBlock across = up;
    across.line = 2;
    across.target = {x, y, z};
    const std::uint64_t before = rt_->job().progress().jobs_started;
    ASSERT_TRUE(op_.upload_program(std::vector<MotionBlock>{up, across, end_block(3)}));
    ASSERT_TRUE(op_.request("cycle.start"));
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    while (rt_->job().progress().jobs_started == before || rt_->job().active()) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline);
      std::this_thread::sleep_for(10ms);  // polling an observable state, as edmhmi does
    }
  };
  const auto measure = [&](const char* reference) {
    const Reply m = op_.request("electrode.measure", {{"reference", reference}});
    EXPECT_TRUE(m) << m.body;
    const std::uint64_t seq = m.body.value("seq", std::uint64_t{0});
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    Json got;
    while (std::chrono::steady_clock::now() < deadline) {
      got = op_.request("electrode.get").body;
      if (got["last_measure"].is_object() && got["last_measure"]["seq"] == seq) break;
      std::this_thread::sleep_for(20ms);
    }
    return got;
  };
  expect_error(op_.request("electrode.measure", {{"reference", "moon"}}), ErrorCode::kBadRequest);
  expect_error(op_.request("electrode.measure"), ErrorCode::kBadRequest);
  ASSERT_TRUE(op_.request("electrode.change", {{"electrode", "E7"},
                                               {"kind", "tube"},
                                               {"size_mm", 1.0},
                                               {"material", "brass"},
                                               {"new_length_mm", 300.0}}));
  // The electrode put in is 12.345 mm shorter than its new length says.
  ASSERT_TRUE(rt_->variables().write("io.electrode_length_mm", 287.655, true));

  run_to(-20.0, -20.0);  // not over the setter
  const Json off = measure("setter");
  EXPECT_FALSE(off["last_measure"]["ok"].get<bool>()) << off;
  EXPECT_NE(off["last_measure"]["error"].get<std::string>().find("not on the tool setter"),
            std::string::npos)
      << off;
  EXPECT_EQ(rt_->electrode().length_mm(), 300.0) << "a failed measurement changes nothing";

  run_to(-45.0, -45.0);
  const Json on = measure("setter");
  ASSERT_TRUE(on["last_measure"]["ok"].get<bool>()) << on;
  EXPECT_NEAR(on["last_measure"]["length_mm"].get<double>(), 287.655, 0.005) << on;
  EXPECT_NEAR(rt_->electrode().length_mm(), 287.655, 0.005);
  EXPECT_TRUE(on["table"][0]["measured"].get<bool>());
  EXPECT_NEAR(on["table"][0]["new_length_mm"].get<double>(), 287.655, 0.005)
      << "a new electrode's first measurement is its new length";
  EXPECT_TRUE(on["measuring"].is_null());
}

}  // namespace
}  // namespace edm::bridge::test
