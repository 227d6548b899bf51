// The audit trail and the log cannot be forged (issue 31, item 8): a client's name with a
// newline wrote a separate audit line "… op=estop -> ok". Every client-supplied text that
// reaches the audit file or the log is quoted, escaped and cut (rt::log_quote), and one peer's
// flood of log lines is rate-limited while the audit file keeps every entry.
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <regex>

#include "bridge_fixture.hpp"
#include "edm/bridge/op_table.hpp"
#include "edm/runtime/log_escape.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;

constexpr const char* kOp = "operator-token-4f1c2a9b";
constexpr const char* kViewer = "viewer-token-77d0e3c5";
const std::string kForged =
    "x\n2026-11-25T11:02:14.002Z session=4 role=operator peer=127.0.0.1:1 op=estop -> ok";

/// Every line of a text file.
std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// `line` without the one non-ASCII text the escaping adds (the cut mark "…").
std::string without_cut_marks(std::string line) {
  for (auto at = line.find("\xe2\x80\xa6"); at != std::string::npos;
       at = line.find("\xe2\x80\xa6")) {
    line.erase(at, 3);
  }
  return line;
}

class AuditEscape : public BridgeFixture {
 protected:
  void SetUp() override {
    // Before any thread logs: the default logger's sinks are not changed while it is in use.
    sink_ = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(100000);
    spdlog::default_logger()->sinks().push_back(sink_);
  }
  void TearDown() override {
    BridgeFixture::TearDown();
    auto& sinks = spdlog::default_logger()->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
  }
  void start_audited() {
    ServerOptions o;
    o.token_file = dir_.file("op.token");
    o.viewer_token_file = dir_.file("viewer.token");
    write_token(o.token_file, kOp, 0600);
    write_token(o.viewer_token_file, kViewer, 0600);
    o.audit_file = dir_.file("audit.log");
    start(o);
  }
  std::vector<std::string> log_lines(const std::string& containing) {
    std::vector<std::string> out;
    for (const std::string& l : sink_->last_formatted()) {
      if (l.find(containing) != std::string::npos) out.push_back(l);
    }
    return out;
  }
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
};

TEST_F(AuditEscape, a_refused_var_write_with_a_newline_in_its_name_is_one_escaped_audit_line) {
  start_audited();
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts(kViewer)), Role::kViewer);
  Client op;
  ASSERT_EQ(op.connect(client_opts(kOp)), Role::kOperator);
  expect_error(viewer.request("var.write", {{"name", kForged}, {"value", 1}}),
               ErrorCode::kForbidden);
  expect_error(op.request("var.write", {{"name", kForged}, {"value", 1}}), ErrorCode::kNotFound);
  const auto file = lines_of(dir_.file("audit.log"));
  ASSERT_EQ(file.size(), 2u) << "exactly one audit line per request";
  EXPECT_NE(file[0].find("role=viewer"), std::string::npos) << file[0];
  EXPECT_NE(file[0].find("name='x\\x0a2026-11-25T11:02:14.002Z session=4"), std::string::npos)
      << file[0];
  EXPECT_TRUE(file[0].ends_with("-> forbidden")) << file[0];
  EXPECT_TRUE(file[1].ends_with("-> not_found")) << file[1];
  const auto logged = log_lines("audit: ");
  ASSERT_EQ(logged.size(), 2u);
  for (const std::string& l : logged) {
    EXPECT_EQ(l.find('\n', 0), l.size() - 1) << "one line: " << l;  // the sink's own newline
    EXPECT_NE(l.find("\\x0a"), std::string::npos) << l;
  }
}

TEST_F(AuditEscape, every_string_field_of_every_audited_op_stays_inside_its_line) {
  start_audited();
  Client op;
  ASSERT_EQ(op.connect(client_opts(kOp)), Role::kOperator);
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts(kViewer)), Role::kViewer);
  // Control characters, quotes, a terminal escape, non-ASCII and 4 KB, in every field an
  // op reads, for every op that is audited (operator-only), by both roles.
  const std::string hostile =
      std::string("a'b\"c\\d\r\n\x1b[2J\x7f\xc3\xa9 op=estop -> ok ") + std::string(4000, 'z');
  Json params = Json::object();
  for (const char* key : {"name", "frame", "axis", "axes", "target", "slot", "checksum", "value",
                          "topics", "percent", "distance", "velocity", "x", "y", "z"}) {
    params[key] = hostile;
  }
  int sent = 0;
  for (const OpSpec& info : op_table()) {
    if (info.access != OpAccess::kOperator) continue;
    for (Client* c : {&op, &viewer}) {
      const Reply r = c->request(info.name, params);
      EXPECT_TRUE(r.ok || r.code.has_value()) << info.name << ": a transport error";
      ++sent;
    }
  }
  const auto file = lines_of(dir_.file("audit.log"));
  ASSERT_EQ(file.size(), static_cast<std::size_t>(sent)) << "one line per request, none forged";
  const std::regex shape(
      R"(^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z session=\d+ role=(operator|viewer) )"
      R"(peer=127\.0\.0\.1:\d+ op=[a-z.]+( .*)? -> [a-z_]+$)");
  for (const std::string& l : file) {
    EXPECT_TRUE(std::regex_match(l, shape)) << l.substr(0, 300);
    EXPECT_TRUE(rt::is_printable_ascii(without_cut_marks(l))) << l.substr(0, 300);
    EXPECT_LT(l.size(), 4000u) << "every name cut at 64 bytes (the request had 60 KB)";
  }
}

TEST_F(AuditEscape, one_peers_flood_is_rate_limited_in_the_log_but_not_in_the_audit_file) {
  start_audited();
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts(kViewer)), Role::kViewer);
  constexpr int kFlood = 300;
  for (int i = 0; i < kFlood; ++i) {
    expect_error(viewer.request("estop"), ErrorCode::kForbidden);
  }
  EXPECT_EQ(lines_of(dir_.file("audit.log")).size(), static_cast<std::size_t>(kFlood));
  const std::size_t logged = log_lines("audit: ").size();
  EXPECT_LE(logged, 30u) << "the burst (20, hellos included) and about one a second";
  EXPECT_GE(logged, 10u);
  // Once a token is back, the next line says how many were not logged.
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  bool summed = false;
  while (!summed && std::chrono::steady_clock::now() < deadline) {
    viewer.request("estop");
    for (const std::string& l : log_lines("audit: ")) {
      summed = summed || l.find("earlier lines from this peer suppressed") != std::string::npos;
    }
    if (!summed) std::this_thread::sleep_for(50ms);  // the bucket refills at 1 line/s
  }
  EXPECT_TRUE(summed) << "the suppressed lines are counted in the log";
}

TEST_F(AuditEscape, a_relayed_peer_is_escaped_in_the_log_and_the_audit) {
  start_audited();
  Client op;
  ClientOptions o = client_opts(kOp);
  o.peer = "10.1.2.3\" op=estop";
  ASSERT_EQ(op.connect(o), Role::kOperator);
  ASSERT_TRUE(op.request("estop"));
  const auto file = lines_of(dir_.file("audit.log"));
  ASSERT_EQ(file.size(), 1u);
  EXPECT_NE(file[0].find(" via=\"10.1.2.3\\\" op=estop\" op=estop -> ok"), std::string::npos)
      << file[0];
  const auto hello = log_lines("hello as operator");
  ASSERT_EQ(hello.size(), 1u);
  EXPECT_NE(hello[0].find("via=\"10.1.2.3\\\" op=estop\""), std::string::npos) << hello[0];
}

}  // namespace
}  // namespace edm::bridge::test
