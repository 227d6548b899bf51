// Acceptance: a third-party client written with a socket and a JSON library only (Python 3
// standard library) runs the scripted session of docs/protocol.md against a real edmplc.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "bridge_fixture.hpp"
#include "support/free_port.hpp"
#include "support/subprocess.hpp"

namespace edm::bridge::test {
namespace {

using edm::test::free_port;

// A free loopback port: bind port 0, read it back, release it (edmplc binds it right after).
TEST(ThirdPartyClient, python_session_against_a_real_edmplc) {
  if (::access("/usr/bin/python3", X_OK) != 0) {
    GTEST_SKIP() << "python3 not installed";
  }
  edm::test::TempDir dir("edm-bridge-py");
  const std::string op = dir.file("op.token");
  const std::string viewer = dir.file("viewer.token");
  write_token(op, "op-7f3a9c0d1e2f3a4b", 0600);
  write_token(viewer, "viewer-51be6c7d8e9f", 0600);
  const std::string cfg = dir.file("machine.yaml");
  std::ofstream(cfg) << kBridgeTestConfig << "bridge: {token_file: " << op
                     << ", viewer_token_file: " << viewer << "}\n";
  const int port = free_port();
  edm::test::Child plc({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", std::to_string(port)});
  ASSERT_TRUE(plc.wait_for_output("bridge: listening on")) << plc.output();

  edm::test::Child py({"/usr/bin/python3",
                       std::string(EDM_TEST_DATA_DIR) + "/bridge/third_party_client.py",
                       std::to_string(port), "op-7f3a9c0d1e2f3a4b", "viewer-51be6c7d8e9f"});
  const int rc = py.wait();
  EXPECT_EQ(rc, 0) << py.output();
  EXPECT_NE(py.output().find("PASS"), std::string::npos) << py.output();

  plc.signal(SIGTERM);
  EXPECT_EQ(plc.wait(), 0) << plc.output();
  EXPECT_NE(plc.output().find("bridge: stopped"), std::string::npos) << plc.output();
}

TEST(ThirdPartyClient, edmplc_refuses_a_world_readable_token_file) {
  edm::test::TempDir dir("edm-bridge-py");
  const std::string op = dir.file("op.token");
  write_token(op, "op-7f3a9c0d1e2f3a4b", 0644);
  const std::string cfg = dir.file("machine.yaml");
  std::ofstream(cfg) << kBridgeTestConfig << "bridge: {token_file: " << op << "}\n";
  edm::test::Child plc(
      {EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", std::to_string(free_port())});
  EXPECT_EQ(plc.wait(), 2) << plc.output();
  EXPECT_NE(plc.output().find("chmod 600"), std::string::npos) << plc.output();
}

}  // namespace
}  // namespace edm::bridge::test
