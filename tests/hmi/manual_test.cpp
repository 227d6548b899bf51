// The client side of the operator's manual functions and work frames (hmi/manual.hpp,
// hmi/work_offsets.hpp): what edmhmi reads from manual.status and offset.get, what it checks
// before sending, and what it sends for touch --set. No runtime needed.
#include "edm/hmi/manual.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "edm/hmi/work_offsets.hpp"

namespace edm::hmi::test {
namespace {

using bridge::Json;
using machining::Vec3;

ManualResult result(std::uint64_t seq, std::string op = "home", bool ok = true) {
  ManualResult r;
  r.seq = seq;
  r.op = std::move(op);
  r.ok = ok;
  return r;
}

TEST(ManualStatus, ReadsTheRuntimesReply) {
  const Json j = Json::parse(R"({"mode": "touch", "busy": true, "seen_seq": 7,
      "referenced": {"X": true, "Y": false, "Z": true}, "may_run_programs": false,
      "result": {"seq": 6, "op": "touch", "target": "center", "ok": true, "error": "none",
                 "x": 12.5, "y": -3.25, "z": 0.0, "size": 4.002, "t_s": 17.5}})");
  ManualStatus s;
  std::string error;
  ASSERT_TRUE(manual_status_from_json(j, s, error)) << error;
  EXPECT_EQ(s.mode, "touch");
  EXPECT_TRUE(s.busy);
  EXPECT_EQ(s.seen_seq, 7u);
  EXPECT_EQ(s.referenced[0], true);
  EXPECT_EQ(s.referenced[1], false);
  EXPECT_EQ(s.referenced[2], true);
  ASSERT_TRUE(s.result.has_value());
  EXPECT_EQ(s.result->seq, 6u);
  EXPECT_EQ(s.result->target, "center");
  EXPECT_EQ(s.result->x_mm, 12.5);
  EXPECT_EQ(s.result->y_mm, -3.25);
  EXPECT_EQ(s.result->size_mm, 4.002);
  EXPECT_EQ(format_manual_result(*s.result),
            "touch center ok X 12.5000 Y -3.2500 Z 0.0000 (machine), bore diameter 4.0020");
}

TEST(ManualStatus, NoResultYetAndWrongTypes) {
  ManualStatus s;
  std::string error;
  ASSERT_TRUE(manual_status_from_json(Json::parse(R"({"mode": "idle", "busy": false})"), s, error));
  EXPECT_FALSE(s.result.has_value());
  EXPECT_FALSE(s.seen_seq.has_value());
  EXPECT_FALSE(manual_status_from_json(Json::parse(R"({"busy": "yes"})"), s, error));
  EXPECT_FALSE(error.empty());
}

TEST(ManualStatus, DoneWhenTakenIdleAndAnsweredForThisRequest) {
  ManualStatus s;
  s.seen_seq = 5;
  s.result = result(5);
  EXPECT_TRUE(manual_done(s, 5, 5));
  s.busy = true;
  EXPECT_FALSE(manual_done(s, 5, 5));  // still moving
  s.busy = false;
  EXPECT_FALSE(manual_done(s, 6, 6));  // our request not taken yet: the result is an older one
  s.seen_seq = 6;
  EXPECT_FALSE(manual_done(s, 6, 6));  // taken, but its result not yet published
  // After a continuous jog (first request 3), jog.stop (6) may answer the jog itself.
  EXPECT_TRUE(manual_done(s, 6, 3));
  s.result.reset();
  EXPECT_FALSE(manual_done(s, 6, 3));
  // A runtime that does not report seen_seq: the result alone decides.
  s.seen_seq.reset();
  s.result = result(9);
  EXPECT_TRUE(manual_done(s, 9, 9));
}

TEST(ManualChecks, AxesJogDistancesAndTouchTargets) {
  std::string e;
  EXPECT_EQ(normalise_axes("zx", e), "ZX");
  EXPECT_TRUE(e.empty());
  EXPECT_EQ(normalise_axes("XYZ", e), "XYZ");
  normalise_axes("XA", e);
  EXPECT_EQ(e, "'XA': axes are X, Y and Z");
  normalise_axes("XX", e);
  EXPECT_EQ(e, "'XX': axis X twice");
  normalise_axes("", e);
  EXPECT_FALSE(e.empty());
  EXPECT_EQ(parse_axis("y"), 'Y');
  EXPECT_FALSE(parse_axis("XY").has_value());
  EXPECT_FALSE(parse_axis("A").has_value());

  EXPECT_TRUE(valid_jog_distance(0.001));
  EXPECT_TRUE(valid_jog_distance(-10.0));
  EXPECT_TRUE(valid_jog_distance(-0.5));
  EXPECT_FALSE(valid_jog_distance(0.0009));
  EXPECT_FALSE(valid_jog_distance(10.001));
  EXPECT_FALSE(valid_jog_distance(std::numeric_limits<double>::quiet_NaN()));

  for (const char* t : {"z", "x+", "x-", "y+", "y-", "center"}) {
    const auto target = parse_touch_target(t);
    ASSERT_TRUE(target.has_value()) << t;
    EXPECT_EQ(to_string(*target), t);
  }
  EXPECT_EQ(parse_touch_target("X+"), TouchTarget::kXPlus);
  EXPECT_FALSE(parse_touch_target("x").has_value());
  EXPECT_FALSE(parse_touch_target("centre").has_value());
}

TEST(ManualChecks, TheJogRefreshIsAThirdOfTheDeadman) {
  EXPECT_EQ(jog_refresh_period(500.0), std::chrono::milliseconds(166));
  EXPECT_EQ(jog_refresh_period(300.0), std::chrono::milliseconds(100));
  EXPECT_EQ(jog_refresh_period(5.0), std::chrono::milliseconds(10));  // at least 10 ms
}

TEST(TouchSet, PutsTheTouchedAxesIntoTheFrame) {
  ManualResult r = result(1, "touch");
  r.x_mm = 1.5;
  r.y_mm = -2.0;
  r.z_mm = -41.25;
  EXPECT_EQ(*offset_set_for_touch("G54", TouchTarget::kZ, r),
            (Json{{"frame", "G54"}, {"z", -41.25}}));
  EXPECT_EQ(*offset_set_for_touch("G55", TouchTarget::kXMinus, r),
            (Json{{"frame", "G55"}, {"x", 1.5}}));
  EXPECT_EQ(*offset_set_for_touch("G54", TouchTarget::kYPlus, r),
            (Json{{"frame", "G54"}, {"y", -2.0}}));
  EXPECT_EQ(*offset_set_for_touch("G59", TouchTarget::kCenter, r),
            (Json{{"frame", "G59"}, {"x", 1.5}, {"y", -2.0}}));
  ManualResult failed = result(2, "touch", false);
  failed.target = "z";
  failed.error = "no_contact";
  ManualResult no_y = r;
  no_y.y_mm.reset();
  EXPECT_FALSE(offset_set_for_touch("G54", TouchTarget::kCenter, no_y).has_value());
  EXPECT_EQ(format_manual_result(failed), "touch z failed: no_contact");
  // A home or jog result's coordinates are not a finding: not printed.
  ManualResult jog = result(3, "jog");
  jog.x_mm = jog.y_mm = jog.z_mm = 0.0;
  EXPECT_EQ(format_manual_result(jog), "jog ok");
  jog.ok = false;
  jog.error = std::string(kStoppedByOperator);
  EXPECT_EQ(format_manual_result(jog), "jog stopped by the operator");
}

TEST(WorkFrames, NamesAndIndices) {
  EXPECT_EQ(frame_name(0), "G54");
  EXPECT_EQ(frame_name(5), "G59");
  EXPECT_EQ(frame_index("G57"), 3);
  EXPECT_EQ(frame_index("g59"), 5);
  EXPECT_FALSE(frame_index("G53").has_value());
  EXPECT_FALSE(frame_index("G59.1").has_value());
  EXPECT_FALSE(frame_index("G5").has_value());
  EXPECT_EQ(to_work({10, 20, 30}, {1, 2, 3}), (Vec3{9, 18, 27}));
  EXPECT_EQ(format_frame(1, {12.5, -3, -41.25}), "G55  X   12.5000  Y   -3.0000  Z  -41.2500");
}

TEST(WorkFrames, ReadsOffsetGetAndWritesItBack) {
  const Json reply = Json::parse(R"({"id": 3, "ok": true, "generation": 4, "frames": {
      "G54": {"x": 1, "y": 2, "z": 3}, "G56": {"z": -40.5}}})");
  WorkOffsets o;
  std::string error;
  ASSERT_TRUE(offsets_from_json(reply, o, error)) << error;
  EXPECT_EQ(o.frame[0], (Vec3{1, 2, 3}));
  EXPECT_EQ(o.frame[1], (Vec3{}));
  EXPECT_EQ(o.frame[2], (Vec3{0, 0, -40.5}));
  WorkOffsets back;
  ASSERT_TRUE(offsets_from_json(to_json(o), back, error)) << error;
  EXPECT_EQ(back, o);
}

TEST(WorkFrames, RefusesWhatIsNotOffsets) {
  WorkOffsets o;
  std::string error;
  EXPECT_FALSE(offsets_from_json(Json::parse("[1]"), o, error));
  EXPECT_FALSE(offsets_from_json(Json::parse(R"({"G54": {}})"), o, error));
  EXPECT_FALSE(offsets_from_json(Json::parse(R"({"frames": {"G53": {"x": 1}}})"), o, error));
  EXPECT_EQ(error, "unknown work frame \"G53\" (G54..G59)");
  EXPECT_FALSE(offsets_from_json(Json::parse(R"({"frames": {"G54": {"x": "1"}}})"), o, error));
  EXPECT_EQ(error, "G54.x: not a finite number (mm)");
  EXPECT_FALSE(offsets_from_json(Json::parse(R"({"frames": {"G54": 5}})"), o, error));
}

}  // namespace
}  // namespace edm::hmi::test
