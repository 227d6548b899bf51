// The static-file side of `edmhmi serve` against hostile paths, and the pure helpers of the web
// server: content types and caching, the issue-21 capability map, the toolpath preview.
#include "edm/hmi/web_static.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <utility>

#include "edm/hmi/web_capabilities.hpp"
#include "edm/hmi/web_job.hpp"
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
  const bridge::Json info = {{"name", "m"}, {"ops", {"jog", "home"}}};
  const std::vector<std::string> probed{"touch"};
  const bridge::Json caps = capabilities_json(info, &probed);
  EXPECT_EQ(caps["source"], "machine.info");
  EXPECT_TRUE(caps["jog"].get<bool>());
  EXPECT_TRUE(caps["reference"].get<bool>());
  EXPECT_FALSE(caps["touch"].get<bool>());
  EXPECT_FALSE(caps["work_coordinates"].get<bool>());
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
