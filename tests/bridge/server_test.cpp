// The bridge server in process, driven by the client library: every op family, every error
// code, auth, limits, slow readers, alarms, trace, program upload, reconnect.
#include "edm/bridge/server.hpp"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "bridge_fixture.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;
using machining::MotionBlock;
using machining::MotionKind;

std::vector<MotionBlock> line_program(std::size_t n) {
  std::vector<MotionBlock> p;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    MotionBlock b;
    b.kind = i % 2 == 0 ? MotionKind::kRapid : MotionKind::kLinear;
    b.line = static_cast<std::int32_t>(i + 1);
    b.col = 1;
    b.target = {static_cast<double>(i % 100) - 50.0, static_cast<double>(i % 37) - 18.0, 5.0};
    b.feed_mm_s = 5.0;
    p.push_back(b);
  }
  MotionBlock end;
  end.kind = MotionKind::kEnd;
  end.line = static_cast<std::int32_t>(n);
  p.push_back(end);
  return p;
}

using RawClient = RawSocket;

class Bridge : public BridgeFixture {};

TEST_F(Bridge, without_tokens_loopback_clients_are_operators_after_hello) {
  start();
  Client c;
  // Before hello: unauthorized (but the session stays open for the hello).
  RawClient raw(server_->port());
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(c.connect(client_opts()), Role::kOperator);
  const Reply s = c.request("status");
  ASSERT_TRUE(s) << s.message;
  EXPECT_EQ(s.body["state"], "READY");
  EXPECT_TRUE(s.body["vars"].is_object());
}

// feed.override (issue 21): operator only, 0..150 %, the machine's override changes; a refused
// value changes nothing.
TEST_F(Bridge, feed_override_is_an_operator_op_within_0_to_150_percent) {
  ServerOptions o;
  o.token_file = dir_.file("op.token");
  o.viewer_token_file = dir_.file("viewer.token");
  write_token(o.token_file, "op-secret-0123456789", 0600);
  write_token(o.viewer_token_file, "viewer-secret-0123456789", 0600);
  start(o);
  Client op;
  ASSERT_EQ(op.connect(client_opts("op-secret-0123456789")), Role::kOperator);
  const auto r = op.request("feed.override", {{"percent", 75}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r.body.value("percent", 0.0), 75.0);
  EXPECT_DOUBLE_EQ(rt_->machine().feed_override(), 0.75);
  for (const Json& bad : {Json(150.5), Json(-1), Json("80"), Json(nullptr), Json(1e308)}) {
    expect_error(op.request("feed.override", {{"percent", bad}}), ErrorCode::kBadRequest);
  }
  expect_error(op.request("feed.override"), ErrorCode::kBadRequest);
  EXPECT_DOUBLE_EQ(rt_->machine().feed_override(), 0.75) << "refused values change nothing";
  EXPECT_TRUE(op.request("feed.override", {{"percent", 0}}));
  EXPECT_TRUE(op.request("feed.override", {{"percent", 150}}));
  EXPECT_DOUBLE_EQ(rt_->machine().feed_override(), 1.5);
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts("viewer-secret-0123456789")), Role::kViewer);
  expect_error(viewer.request("feed.override", {{"percent", 10}}), ErrorCode::kForbidden);
  EXPECT_DOUBLE_EQ(rt_->machine().feed_override(), 1.5);
}

TEST_F(Bridge, every_error_code_is_reachable) {
  ServerOptions o;
  o.token_file = dir_.file("op.token");
  o.viewer_token_file = dir_.file("viewer.token");
  write_token(o.token_file, "op-secret-0123456789", 0600);
  write_token(o.viewer_token_file, "viewer-secret-0123456789", 0600);
  o.max_sessions = 3;
  start(o);

  Client op;
  ASSERT_EQ(op.connect(client_opts("op-secret-0123456789")), Role::kOperator);
  expect_error(op.request_raw("{\"id\": 1, oops"), ErrorCode::kBadJson);
  expect_error(op.request("subscribe", {{"topics", 5}}), ErrorCode::kBadRequest);
  expect_error(op.request("subscribe", {{"topics", {"status"}}, {"rate_hz", 101}}),
               ErrorCode::kBadRequest);
  expect_error(op.request("frobnicate"), ErrorCode::kUnknownOp);
  expect_error(op.request("cycle.resume"), ErrorCode::kInvalidState);
  expect_error(op.request("var.read", {{"name", "no.such.var"}}), ErrorCode::kNotFound);
  expect_error(op.request("program.chunk", {{"first", 0}, {"blocks", Json::array()}}),
               ErrorCode::kNotFound);
  expect_error(op.request_raw(std::string(2u << 20, 'x')), ErrorCode::kTooLarge);
  EXPECT_TRUE(op.request("ping")) << "the session lives on after too_large";

  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts("viewer-secret-0123456789")), Role::kViewer);
  expect_error(viewer.request("cycle.start"), ErrorCode::kForbidden);
  EXPECT_TRUE(viewer.request("status"));

  // unauthorized: a wrong token (the session is then closed), and any op before hello.
  Client bad;
  try {
    bad.connect(client_opts("guess"));
    ADD_FAILURE() << "a wrong token was accepted";
  } catch (const ClientError& e) {
    ASSERT_TRUE(e.code().has_value());
    EXPECT_EQ(*e.code(), ErrorCode::kUnauthorized);
  }

  // invalid_state: a job is active, so a program cannot be swapped in (the op-state table) ...
  const auto prog = line_program(10);
  ASSERT_EQ(rt_->job().load(prog), rt::LoadResult::kOk);
  ASSERT_TRUE(rt_->job().rt_begin());  // stands in for the RT job sequencer
  expect_error(op.upload_program(prog), ErrorCode::kInvalidState);
  rt_->job().rt_finish(rt::JobOutcome::kAborted);
  EXPECT_TRUE(op.upload_program(prog));
  // ... and a full house refuses the next connection with busy.
  Client third;
  ASSERT_NO_THROW(third.connect(client_opts("viewer-secret-0123456789")));
  Client fourth;
  try {
    fourth.connect(client_opts("viewer-secret-0123456789"));
    ADD_FAILURE() << "max_sessions was not enforced";
  } catch (const ClientError& e) {
    ASSERT_TRUE(e.code().has_value()) << e.what();
    EXPECT_EQ(*e.code(), ErrorCode::kBusy);
  }
  EXPECT_GE(server_->stats().sessions_refused, 1u);
}

TEST_F(Bridge, requests_before_hello_are_unauthorized) {
  start();
  RawClient raw(server_->port());
  ASSERT_TRUE(raw.ok());
  raw.send("{\"id\":1,\"op\":\"status\"}\n");
  const Json r = Json::parse(raw.read_line(5s), nullptr, false);
  EXPECT_EQ(r.value("id", 0), 1);
  EXPECT_EQ(r["error"]["code"], "unauthorized");
  raw.send("{\"id\":2,\"op\":\"hello\",\"protocol\":1}\n");
  EXPECT_EQ(Json::parse(raw.read_line(5s), nullptr, false).value("role", ""), "operator")
      << "the session stays open for a hello";
}

TEST_F(Bridge, ten_thousand_block_program_commits_and_errors_name_the_line) {
  start();
  Client c;
  c.connect(client_opts());
  const auto prog = line_program(10'000);
  const Reply r = c.upload_program(prog, 1000);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["blocks"], 10'000);
  EXPECT_EQ(rt_->job().loaded_blocks(), 10'000u);
  EXPECT_EQ(r.body["checksum"], format_checksum(program_checksum(prog)));

  // A block beyond the soft limits is refused at commit, naming its G-code line and column.
  auto bad = line_program(100);
  bad[41].target.x = 500.0;
  bad[41].line = 77;
  bad[41].col = 4;
  const Reply e = c.upload_program(bad);
  expect_error(e, ErrorCode::kBadRequest);
  EXPECT_EQ(e.message.rfind("line 77:4: ", 0), 0u) << e.message;
  EXPECT_EQ(e.details["issues"][0]["line"], 77);
  EXPECT_EQ(rt_->job().loaded_blocks(), 10'000u) << "the old program stays";

  // A wrong checksum is refused.
  ASSERT_TRUE(c.request("program.begin", {{"blocks", 1}}));
  ASSERT_TRUE(c.request("program.chunk", {{"first", 0}, {"blocks", {to_json(prog.back())}}}));
  expect_error(c.request("program.commit", {{"checksum", "00000000"}}), ErrorCode::kBadRequest);
  // Out-of-order chunks too.
  ASSERT_TRUE(c.request("program.begin", {{"blocks", 2}}));
  expect_error(c.request("program.chunk", {{"first", 1}, {"blocks", {to_json(prog.back())}}}),
               ErrorCode::kBadRequest);
  expect_error(c.request("program.begin", {{"blocks", 2'000'000}}), ErrorCode::kTooLarge);
}

TEST_F(Bridge, status_subscription_has_the_rate_and_no_seq_gaps) {
  start();
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client c;
  connect_with_events(c, sink);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(c.subscribe({"status"}, 50));
  const auto ev = sink.wait_for("status", 50);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(ev.size(), 50u);
  expect_no_gaps(ev);
  EXPECT_EQ(ev.front()["seq"], 1);
  EXPECT_GT(elapsed_s, 0.9) << "50 events at 50 Hz take about 1 s, not less";
  EXPECT_GT(ev.back()["cycle"].get<std::uint64_t>(), ev.front()["cycle"].get<std::uint64_t>())
      << "snapshots come from the running I/O task";
}

TEST_F(Bridge, a_stalled_100hz_subscriber_delays_neither_others_nor_the_tasks) {
  ServerOptions o;
  o.queue_limit = 16;
  o.stall_timeout = 300ms;
  o.send_buffer_bytes = 4096;
  start(o);
  RawClient slow(server_->port(), /*rcvbuf=*/2048);
  ASSERT_TRUE(slow.ok());
  slow.send(
      "{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n"
      "{\"id\":2,\"op\":\"subscribe\",\"topics\":[\"status\"],\"rate_hz\":100}\n");
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client good;
  connect_with_events(good, sink);
  const std::uint64_t cycles0 = rt_->tasks().front()->cycles();
  ASSERT_TRUE(good.subscribe({"status"}, 50));
  const auto ev = sink.wait_for("status", 100);
  ASSERT_EQ(ev.size(), 100u);
  expect_no_gaps(ev);
  for (const auto& e : ev) {
    EXPECT_EQ(e["dropped"], 0) << "the good subscriber lost nothing";
  }
  // The 1 kHz task kept running through the ~2 s (generous bound: shared CI machine).
  EXPECT_GT(rt_->tasks().front()->cycles() - cycles0, 1000u);
  // The stalled one is dropped, then disconnected.
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (server_->stats().slow_disconnects == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::yield();  // polling a process-wide counter with a deadline
  }
  EXPECT_EQ(server_->stats().slow_disconnects, 1u);
  EXPECT_GT(server_->stats().events_dropped, 0u);
  EXPECT_TRUE(good.request("ping")) << "the good client is still served";
}

TEST_F(Bridge, alarms_reach_subscribers_and_the_log_alike) {
  start();
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client c;
  connect_with_events(c, sink);
  ASSERT_TRUE(c.subscribe({"alarm"}));
  rt::Alarm a = warning_alarm("test", "a test alarm");
  a.value = 1.5;
  rt_->machine().raise(a);
  const auto ev = sink.wait_for("alarm", 1);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0]["code"], 101);
  EXPECT_EQ(ev[0]["text"], "a test alarm");
  EXPECT_EQ(ev[0]["severity"], "warning");
}

TEST_F(Bridge, estop_and_reset_drive_the_state_machine) {
  start();
  Client c;
  c.connect(client_opts());
  const Reply e = c.request("estop");
  ASSERT_TRUE(e) << e.message;
  EXPECT_EQ(e.body["state"], "ESTOP");
  expect_error(c.request("cycle.start"), ErrorCode::kInvalidState);
  EXPECT_EQ(c.request("reset").body["state"], "READY");
  EXPECT_EQ(c.request("cycle.start").body["state"], "RUNNING");
  EXPECT_EQ(c.request("cycle.hold").body["state"], "HOLD");
  EXPECT_EQ(c.request("cycle.resume").body["state"], "RUNNING");
  EXPECT_EQ(c.request("cycle.stop").body["state"], "READY");
}

TEST_F(Bridge, a_machine_that_runs_part_programs_needs_one_to_start) {
  start();
  rt_->job().attach_runner();  // as EdmJob does at configure time
  Client c;
  c.connect(client_opts());
  const Reply r = c.request("cycle.start");
  expect_error(r, ErrorCode::kInvalidState);
  EXPECT_NE(r.message.find("no part program loaded"), std::string::npos) << r.message;
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady);
  ASSERT_TRUE(c.upload_program(line_program(3)));
  EXPECT_EQ(c.request("cycle.start").body["state"], "RUNNING");
}

TEST_F(Bridge, variables_list_read_write_force) {
  start();
  Client c;
  c.connect(client_opts());
  const Reply l = c.request("var.list", {{"prefix", "chain.g."}});
  ASSERT_TRUE(l);
  EXPECT_GE(l.body["vars"].size(), 3u);
  EXPECT_TRUE(c.request("var.write", {{"name", "chain.g.k"}, {"value", 2.0}}));
  expect_error(c.request("var.write", {{"name", "chain.g.out"}, {"value", 2.0}}),
               ErrorCode::kBadRequest);
  ASSERT_TRUE(c.request("var.force", {{"name", "chain.g.in"}, {"value", 0.25}}));
  const Reply forced = c.request("var.list", {{"prefix", "chain.g.in"}});
  EXPECT_EQ(forced.body["vars"][0]["forced"], true);
  EXPECT_TRUE(c.request("var.unforce", {{"name", "chain.g.in"}}));
  const Reply r = c.request("var.read", {{"names", {"chain.g.k", "io.ai0"}}});
  ASSERT_TRUE(r);
  EXPECT_TRUE(r.body["values"].contains("io.ai0"));
  const Reply st = c.request("tasks.stats");
  ASSERT_TRUE(st);
  EXPECT_EQ(st.body["tasks"][0]["name"], "fast");
  EXPECT_GE(st.body["bridge"]["requests"].get<int>(), 7);
}

TEST_F(Bridge, trace_streams_samples_from_its_own_tap) {
  start();
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client c;
  connect_with_events(c, sink);
  expect_error(c.trace_start({"nope.x"}), ErrorCode::kNotFound);
  ASSERT_TRUE(c.trace_start({"chain.g.out", "io.ai0"}));
  const auto ev = sink.wait_for("trace", 3);
  ASSERT_GE(ev.size(), 3u);
  EXPECT_EQ(ev[0]["task"], "fast");
  EXPECT_EQ(ev[0]["vars"].size(), 2u);
  ASSERT_FALSE(ev[0]["samples"].empty());
  EXPECT_EQ(ev[0]["samples"][0].size(), 4u);  // t_s, cycle, two values
  // Consecutive cycles: every cycle is sampled (1 kHz task, tap ring far from full).
  const auto& s = ev[1]["samples"];
  for (std::size_t i = 1; i < s.size(); ++i) {
    EXPECT_EQ(s[i][1].get<std::uint64_t>(), s[i - 1][1].get<std::uint64_t>() + 1);
  }
  EXPECT_TRUE(c.trace_stop());
}

TEST_F(Bridge, reconnect_replays_the_subscription) {
  start();
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client c;
  connect_with_events(c, sink);
  ASSERT_TRUE(c.subscribe({"status"}, 20));
  ASSERT_EQ(sink.wait_for("status", 2).size(), 2u);
  c.reconnect();
  EXPECT_EQ(c.connections(), 2u);
  // The new session's seq restarts at 1: a second "seq 1" status event shows the replay.
  const bool restarted = sink.wait_until([](const std::vector<Json>& all) {
    return std::count_if(all.begin(), all.end(), [](const Json& e) {
             return e.value("event", "") == "status" && e["seq"] == 1;
           }) >= 2;
  });
  EXPECT_TRUE(restarted);
}

TEST_F(Bridge, auto_reconnect_after_the_server_drops_the_session) {
  ServerOptions o;
  o.read_timeout = 300ms;  // the server closes idle sessions fast
  start(o);
  // Declared before the client, so they outlive it: its thread calls the handler (down) while
  // the client closes at the end of the test.
  std::mutex mu;
  std::condition_variable cv;
  int ups = 0;
  Client c;
  c.set_connection_handler([&](bool up) {
    std::lock_guard lock(mu);
    ups += up ? 1 : 0;
    cv.notify_all();
  });
  ClientOptions co = client_opts();
  co.keepalive = 10s;  // longer than the server's timeout: the session will be dropped
  co.auto_reconnect = true;
  c.connect(co);
  std::unique_lock lock(mu);
  EXPECT_TRUE(cv.wait_for(lock, 10s, [&] { return ups >= 2; })) << "no automatic reconnect";
  EXPECT_GE(server_->stats().timeouts, 1u);
}

TEST_F(Bridge, idle_sessions_time_out) {
  ServerOptions o;
  o.read_timeout = 200ms;
  start(o);
  RawClient raw(server_->port());
  ASSERT_TRUE(raw.ok());
  EXPECT_TRUE(raw.closed_within(5s));
  EXPECT_EQ(server_->stats().timeouts, 1u);
}

// ---- start-up refusals and auth helpers -------------------------------------------------------

TEST(BridgeAuth, token_files_readable_by_others_are_refused) {
  edm::test::TempDir dir("edm-bridge-auth");
  const std::string f = dir.file("op.token");
  write_token(f, "secret-0123456789abc", 0644);
  try {
    load_tokens(f, "");
    ADD_FAILURE() << "a world-readable token file was accepted";
  } catch (const BridgeError& e) {
    EXPECT_NE(std::string(e.what()).find("mode 0644"), std::string::npos) << e.what();
  }
  write_token(f, "secret-0123456789abc", 0600);
  EXPECT_EQ(load_tokens(f, "").operator_token, "secret-0123456789abc");
  write_token(f, "  \n", 0600);
  EXPECT_THROW(load_tokens(f, ""), BridgeError);
  EXPECT_THROW(load_tokens(dir.file("missing"), ""), BridgeError);
}

TEST(BridgeAuth, roles_and_constant_time_compare) {
  EXPECT_TRUE(constant_time_equal("abc", "abc"));
  EXPECT_FALSE(constant_time_equal("abc", "abd"));
  EXPECT_FALSE(constant_time_equal("abc", "ab"));
  EXPECT_FALSE(constant_time_equal("abc", "abcd"));
  const TokenSet none;
  EXPECT_EQ(authenticate(none, "", true), Role::kOperator);
  EXPECT_EQ(authenticate(none, "", false), std::nullopt);
  const TokenSet both{"op", "view"};
  EXPECT_EQ(authenticate(both, "op", false), Role::kOperator);
  EXPECT_EQ(authenticate(both, "view", true), Role::kViewer);
  EXPECT_EQ(authenticate(both, "", true), std::nullopt);
  EXPECT_TRUE(is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(is_loopback_address("::1"));
  EXPECT_TRUE(is_loopback_address("::ffff:127.0.0.1"));
  EXPECT_FALSE(is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(is_loopback_address("not-an-ip"));
}

TEST(BridgeStart, a_network_bind_without_a_token_is_refused) {
  auto rt = edm::test::build_from_text(kBridgeTestConfig);
  ServerOptions o;
  o.bind = "0.0.0.0";
  o.port = 0;
  Server s(*rt, o);
  try {
    s.start();
    ADD_FAILURE() << "started on 0.0.0.0 without a token";
  } catch (const BridgeError& e) {
    EXPECT_NE(std::string(e.what()).find("no token_file"), std::string::npos) << e.what();
  }
}

TEST(BridgeStart, unknown_status_vars_are_refused) {
  auto rt = edm::test::build_from_text(kBridgeTestConfig);
  ServerOptions o;
  o.port = 0;
  o.status_vars = {"io.ai0", "no.such.pin"};
  Server s(*rt, o);
  EXPECT_THROW(s.start(), BridgeError);
}

}  // namespace
}  // namespace edm::bridge::test
