// edmplc --check refuses what the bridge would refuse at start (issue 17, item 10): a check that
// passes must mean the runtime starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "bridge_fixture.hpp"
#include "support/subprocess.hpp"

namespace edm::bridge::test {
namespace {

class CheckConsistency : public ::testing::Test {
 protected:
  /// Writes a config with the given `bridge:` section body; returns its path.
  std::string config_with(const std::string& bridge) {
    const std::string path = dir_.file("machine.yaml");
    std::ofstream(path) << kBridgeTestConfig << "bridge:\n" << bridge;
    return path;
  }
  int check(const std::string& config, std::string& output) {
    edm::test::Child c({EDM_EDMPLC_PATH, "--config", config, "--check"});
    const int code = c.wait();
    output = c.output();
    return code;
  }
  edm::test::TempDir dir_{"edm-check"};
};

TEST_F(CheckConsistency, bridge_settings_the_runtime_refuses_fail_the_check_at_the_bridge_line) {
  const std::string loose = dir_.file("loose.token");
  write_token(loose, "operator-token-4f1c2a9b", 0644);
  const std::string tight = dir_.file("tight.token");
  write_token(tight, "operator-token-4f1c2a9b", 0600);
  const std::string short_tok = dir_.file("short.token");
  write_token(short_tok, "abc", 0600);
  // The bridge map's first key, the line after `bridge:`.
  const int bridge_line =
      2 + static_cast<int>(std::count(kBridgeTestConfig.begin(), kBridgeTestConfig.end(), '\n'));
  struct Case {
    std::string bridge;
    std::string why;
  };
  const std::vector<Case> refused = {
      {"  port: 7731\n  token_file: " + loose + "\n", "group/others"},
      {"  port: 7731\n  token_file: " + short_tok + "\n", "at least 16"},
      {"  port: 7731\n  bind: 0.0.0.0\n", "no token_file"},
      {"  port: 7731\n  bind: 0.0.0.0\n  token_file: " + tight + "\n", "bridge.tls"},
      {"  port: 7731\n  tls: {cert: " + dir_.file("none.pem") + ", key: " + tight + "}\n",
       "none.pem: No such file"},
  };
  for (const auto& c : refused) {
    std::string out;
    EXPECT_EQ(check(config_with(c.bridge), out), 2) << c.bridge << out;
    EXPECT_NE(out.find("machine.yaml:" + std::to_string(bridge_line) + ":"), std::string::npos)
        << out;
    EXPECT_NE(out.find(c.why), std::string::npos) << out;
  }
  std::string out;
  EXPECT_EQ(check(config_with("  port: 7731\n  bind: 0.0.0.0\n  token_file: " + tight +
                              "\n  insecure_plaintext: true\n"),
                  out),
            0)
      << out;
  EXPECT_EQ(check(config_with("  port: 0\n  token_file: " + loose + "\n"), out), 0)
      << "no bridge, nothing to refuse: " << out;
}

}  // namespace
}  // namespace edm::bridge::test
