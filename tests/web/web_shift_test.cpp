// The page's queue and electrode measurement in `edmhmi serve` (hmi/include/edm/hmi/web_shift.hpp):
// what it refuses (bounds, wrong state), its change notification, and a queue whose edmplc is
// not there ending with why. The shift against a real edmplc: tests/web/shift.test.mjs.
#include "edm/hmi/web_shift.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <limits>
#include <thread>

#include "support/free_port.hpp"

namespace edm::hmi {
namespace {

using bridge::Json;

QueueItem item(int repeat = 1, double step_x = 0.0) {
  QueueItem i;
  i.part = "p.nc";
  i.text = "M30\n";
  i.repeat = repeat;
  i.step_x_mm = step_x;
  return i;
}

ConnectionSettings nowhere() {
  ConnectionSettings s;
  s.host = "127.0.0.1";
  s.port = static_cast<std::uint16_t>(edm::test::free_port());  // nothing listens there
  return s;
}

TEST(WebShift, RefusesRepeatsStepsAndItemsOutOfBoundsAndKeepsTheQueue) {
  WebShift shift(nowhere());
  EXPECT_FALSE(shift.add(item(0)).value("ok", true));
  EXPECT_FALSE(shift.add(item(WebShift::kMaxRepeat + 1)).value("ok", true));
  EXPECT_FALSE(shift.add(item(1, 1e6)).value("ok", true));
  EXPECT_FALSE(shift.add(item(1, std::numeric_limits<double>::quiet_NaN())).value("ok", true));
  for (std::size_t k = 0; k < WebShift::kMaxItems; ++k) ASSERT_TRUE(shift.add(item(2, 10.0))["ok"]);
  const Json full = shift.add(item());
  EXPECT_FALSE(full["ok"]);
  EXPECT_EQ(full["code"], "bad_request");
  const Json s = shift.snapshot();
  ASSERT_EQ(s["items"].size(), WebShift::kMaxItems) << "a refusal loses nothing queued";
  EXPECT_EQ(s["items"][0]["repeat"], 2);
  EXPECT_EQ(s["items"][0]["step_x"], 10.0);
  EXPECT_TRUE(shift.control("clear")["ok"]);
  EXPECT_TRUE(shift.snapshot()["items"].empty());
}

TEST(WebShift, ControlAndMeasureInTheWrongStateAreRefusedWithACode) {
  WebShift shift(nowhere());
  EXPECT_EQ(shift.control("start")["message"], "the queue is empty: add a program first");
  EXPECT_EQ(shift.control("stop")["code"], "bad_state");
  EXPECT_EQ(shift.control("rewind")["code"], "bad_request");
  EXPECT_EQ(shift.measure("table", "")["code"], "bad_request");
}

TEST(WebShift, TellsAChangeOnceThenNothingUntilTheNext) {
  WebShift shift(nowhere());
  (void)shift.take_changes();
  EXPECT_TRUE(shift.take_changes().is_null());
  ASSERT_TRUE(shift.add(item())["ok"]);
  const Json c = shift.take_changes();
  ASSERT_TRUE(c.is_object());
  EXPECT_EQ(c["items"].size(), 1u);
  EXPECT_TRUE(shift.take_changes().is_null());
}

/// Waits (bounded) for `pred` on the snapshot: the procedures run on threads of their own.
template <typename Pred>
Json wait_for(const WebShift& shift, Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  Json s = shift.snapshot();
  while (!pred(s) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling its observable state
    s = shift.snapshot();
  }
  return s;
}

TEST(WebShift, AQueueAndAMeasurementWithoutEdmplcEndSayingWhyAndKeepTheItems) {
  WebShift shift(nowhere());
  ASSERT_TRUE(shift.add(item(3))["ok"]);
  ASSERT_TRUE(shift.control("start")["ok"]);
  const Json q = wait_for(shift, [](const Json& s) { return !s["running"].get<bool>(); });
  EXPECT_EQ(q["ok"], false);
  EXPECT_NE(q["message"].get<std::string>().find("cannot reach edmplc"), std::string::npos)
      << q["message"];
  EXPECT_EQ(q["items"].size(), 1u);
  ASSERT_TRUE(shift.measure("setter", "")["ok"]);
  const Json m = wait_for(
      shift, [](const Json& s) { return s["measure"].value("running", true) == false; })["measure"];
  EXPECT_EQ(m["ok"], false);
  EXPECT_NE(m["error"].get<std::string>().find("cannot reach edmplc"), std::string::npos) << m;
}

}  // namespace
}  // namespace edm::hmi
