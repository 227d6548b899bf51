// The static-file side of `edmhmi serve` against hostile paths, and the pure helpers of the web
// server: content types and caching, the issue-21 capability map, the toolpath preview.
#include "edm/hmi/web_static.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <utility>

#include "edm/hmi/web_capabilities.hpp"
#include "edm/hmi/web_job.hpp"
#include "edm/hmi/web_manual.hpp"
#include "support/temp_dir.hpp"

namespace edm::hmi::test {
namespace {

namespace fs = std::filesystem;

class StaticRoot : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(root() / "assets");
    std::ofstream(root() / "index.html") << "<!doctype html>";
    std::ofstream(root() / "assets" / "app-1234.js") << "1";
    std::ofstream(dir_.path() / "secret.txt") << "outside the root";
  }
  [[nodiscard]] fs::path root() const { return dir_.path() / "web"; }
  [[nodiscard]] std::optional<fs::path> get(std::string_view target) const {
    return resolve_static_path(root(), target);
  }
  edm::test::TempDir dir_{"edm-web"};
};

TEST_F(StaticRoot, slash_and_directories_serve_their_index) {
  ASSERT_TRUE(get("/"));
  EXPECT_EQ(get("/")->filename(), "index.html");
  EXPECT_EQ(get("/?v=1#x")->filename(), "index.html");
  EXPECT_EQ(get("/assets/app-1234.js")->filename(), "app-1234.js");
}

TEST_F(StaticRoot, dot_dot_and_encoded_dot_dot_never_leave_the_root) {
  for (const char* t :
       {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E%2Fsecret.txt",
        "/assets/%2e%2e/%2e%2e/secret.txt", "/./index.html", "//etc/passwd", "/..%5csecret.txt",
        "/index.html%00.js", "/%zz", "/%2", "index.html", ""}) {
    EXPECT_FALSE(get(t)) << t;
  }
}

TEST_F(StaticRoot, a_symlink_out_of_the_root_is_refused) {
  fs::create_symlink(dir_.path() / "secret.txt", root() / "link.txt");
  EXPECT_FALSE(get("/link.txt"));
}

TEST(WebStatic, content_types_and_caching) {
  const std::pair<const char*, const char*> types[] = {{"a/index.html", "text/html; charset=utf-8"},
                                                       {"x.js", "text/javascript; charset=utf-8"},
                                                       {"x.css", "text/css; charset=utf-8"},
                                                       {"x.bin", "application/octet-stream"}};
  for (const auto& [path, type] : types) EXPECT_EQ(content_type_for(path), type) << path;
  EXPECT_EQ(cache_control_for("/"), "no-cache");
  EXPECT_EQ(cache_control_for("/index.html"), "no-cache");
  EXPECT_EQ(cache_control_for("/assets/index-abc.js"), "public, max-age=31536000, immutable");
}

TEST(WebCapabilities, a_capability_list_in_machine_info_wins_over_the_probe) {
  const bridge::Json info = {{"name", "m"},
                             {"ops", {"jog", "home"}},
                             {"manual", {{"available", true}, {"home", true}, {"touch", true}}}};
  const std::vector<std::string> probed{"touch"};
  const bridge::Json caps = capabilities_json(info, &probed);
  EXPECT_EQ(caps["source"], "machine.info");
  EXPECT_TRUE(caps["jog"].get<bool>());
  EXPECT_TRUE(caps["reference"].get<bool>());
  EXPECT_FALSE(caps["touch"].get<bool>());
  EXPECT_EQ(caps["why"]["touch"], "not supported by this edmplc");
  EXPECT_FALSE(caps["work_coordinates"].get<bool>());
  EXPECT_FALSE(caps["mdi"].get<bool>());
}

TEST(WebCapabilities, an_op_the_machine_has_not_wired_is_not_offered_and_says_why) {
  const bridge::Json info = {
      {"ops", {"home", "jog", "jog.stop", "touch", "manual.status", "offset.get", "offset.set"}},
      {"manual", {{"available", true}, {"home", false}, {"touch", true}, {"deadman_ms", 500}}}};
  const bridge::Json caps = capabilities_json(info, nullptr);
  EXPECT_FALSE(caps["reference"].get<bool>());
  EXPECT_EQ(caps["why"]["reference"], "this machine has no reference switches wired");
  for (const char* k : {"jog", "touch", "offsets", "mdi", "run_from", "dry_run", "work_coordinates",
                        "manual_status"}) {
    EXPECT_TRUE(caps[k].get<bool>()) << k;
  }
  EXPECT_EQ(caps["manual"]["deadman_ms"], 500);
}

TEST(WebCapabilities, without_a_job_sequencer_mdi_and_jog_are_not_offered) {
  const bridge::Json info = {{"ops", {"jog", "offset.get", "offset.set"}},
                             {"manual", {{"available", false}}}};
  const bridge::Json caps = capabilities_json(info, nullptr);
  EXPECT_FALSE(caps["jog"].get<bool>());
  EXPECT_FALSE(caps["mdi"].get<bool>());
  EXPECT_TRUE(caps["offsets"].get<bool>());
}

TEST(WebCapabilities, the_probe_asks_each_op_once) {
  const std::vector<std::string> ops = operator_function_ops();
  EXPECT_EQ(std::count(ops.begin(), ops.end(), "offset.get"), 1);
  EXPECT_EQ(ops.size(), 6u);  // home jog touch offset.set offset.get feed.override
}

TEST(WebJogTiming, on_a_real_clock_a_silent_browser_is_stopped_within_the_dead_man) {
  const JogTiming t = jog_timing(500.0, 1.0);
  EXPECT_DOUBLE_EQ(t.deadman_ms, 500.0);
  EXPECT_NEAR(t.refresh_ms, 166.7, 0.1);
  EXPECT_DOUBLE_EQ(t.hold_window_ms, 250.0);
  EXPECT_LT(t.hold_window_ms + t.refresh_ms, t.deadman_ms);
  EXPECT_LE(3 * t.held_ms, t.hold_window_ms + 1e-9);  // three "held" per window
}

TEST(WebJogTiming, a_faster_machine_clock_shortens_the_refresh_not_the_browsers_floor) {
  // The browser tests: 5 s of machine time at 10x is the default 500 ms on a real clock.
  const JogTiming t = jog_timing(5000.0, 10.0);
  const JogTiming real = jog_timing(500.0, 1.0);
  EXPECT_DOUBLE_EQ(t.deadman_ms, real.deadman_ms);
  EXPECT_DOUBLE_EQ(t.refresh_ms, real.refresh_ms);
  EXPECT_DOUBLE_EQ(t.hold_window_ms, real.hold_window_ms);
  const JogTiming fast = jog_timing(500.0, 10.0);
  EXPECT_DOUBLE_EQ(fast.hold_window_ms, kMinHoldWindowMs);
  EXPECT_NEAR(fast.refresh_ms, 16.7, 0.1);
  const JogTiming bad = jog_timing(-1.0, 0.0);  // nonsense in: the defaults
  EXPECT_DOUBLE_EQ(bad.deadman_ms, 500.0);
}

TEST(WebCapabilities, without_a_list_or_probe_nothing_is_offered) {
  const bridge::Json caps = capabilities_json({{"name", "m"}}, nullptr);
  EXPECT_EQ(caps["source"], "none");
  for (const OperatorFunction& f : kOperatorFunctions) {
    EXPECT_FALSE(caps[std::string(f.key)].get<bool>()) << f.key;
  }
}

TEST(WebToolpath, a_drill_goes_down_and_back_an_orbit_closes_and_long_paths_are_thinned) {
  using machining::MotionBlock;
  using machining::MotionKind;
  std::vector<MotionBlock> blocks(3);
  blocks[0].kind = MotionKind::kRapid;
  blocks[0].target = {5, 5, 0.5};
  blocks[1].kind = MotionKind::kDrill;
  blocks[1].target = {5, 5, -12};
  blocks[2].kind = MotionKind::kOrbitFinish;
  blocks[2].final_radius_mm = 0.6;
  const bridge::Json pts = toolpath_points(blocks, {0, 0, 5}, 1000);
  ASSERT_GE(pts.size(), 5u);
  EXPECT_EQ(pts[2][2].get<double>(), -12.0);  // the hole bottom
  EXPECT_EQ(pts[3][2].get<double>(), 0.5);    // back where the drilling block started
  EXPECT_NEAR(pts.back()[0].get<double>(), 5.0, 1e-9);
  double max_x = 0;
  for (const auto& p : pts) max_x = std::max(max_x, p[0].get<double>());
  EXPECT_NEAR(max_x, 5.6, 1e-9);  // the orbit reaches the final radius
  EXPECT_EQ(toolpath_points(blocks, {0, 0, 5}, 4).size(), 4u);
}

}  // namespace
}  // namespace edm::hmi::test
