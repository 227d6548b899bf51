// Hostile and broken clients (issue 17): each test is the regression test of one class of fault
// an outside tester found, tried with inputs of the same kind rather than the one example.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "bridge_fixture.hpp"
#include "edm/apps/subprocess.hpp"
#include "edm/bridge/hello_throttle.hpp"
#include "support/memory_transport.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;
using edm::test::MemoryPeer;

Json parse(const std::string& line) { return Json::parse(line, nullptr, false); }

template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout = 10s) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > end) {
      return false;
    }
    std::this_thread::yield();  // polling a counter of the server's, with a deadline
  }
  return true;
}

class Hardening : public BridgeFixture {
 protected:
  /// A viewer and an operator token (both long enough).
  ServerOptions with_tokens(ServerOptions o = {}) {
    o.token_file = dir_.file("op.token");
    o.viewer_token_file = dir_.file("viewer.token");
    write_token(o.token_file, kOp, 0600);
    write_token(o.viewer_token_file, kViewer, 0600);
    return o;
  }
  static constexpr const char* kOp = "operator-token-4f1c2a9b";
  static constexpr const char* kViewer = "viewer-token-77d0e3c5";
};

// ---- 1. nesting: bounded before parsing, never echoed -----------------------------------------

TEST(StrictJson, nesting_is_bounded_and_duplicate_keys_are_refused) {
  Json j;
  std::string why;
  const auto nested = [](int depth, char open, char close) {
    return std::string(static_cast<std::size_t>(depth), open) +
           std::string(static_cast<std::size_t>(depth), close);
  };
  EXPECT_TRUE(parse_json_strict(nested(kMaxJsonDepth, '[', ']'), j, why)) << why;
  EXPECT_FALSE(parse_json_strict(nested(kMaxJsonDepth + 1, '[', ']'), j, why));
  EXPECT_FALSE(parse_json_strict(std::string(200000, '['), j, why)) << "unterminated, deep";
  std::string objects;
  for (int i = 0; i <= kMaxJsonDepth; ++i) {
    objects += "{\"a\":";
  }
  objects += "1" + std::string(kMaxJsonDepth + 1, '}');
  EXPECT_FALSE(parse_json_strict(objects, j, why));
  // Brackets inside strings are text, not nesting.
  EXPECT_TRUE(parse_json_strict("{\"s\":\"" + std::string(1000, '[') + "\\\"[\"}", j, why));
  // Duplicate keys at any level, however spelled the same.
  EXPECT_FALSE(parse_json_strict(R"({"op":"ping","op":"estop"})", j, why));
  EXPECT_FALSE(parse_json_strict(R"({"a":{"x":1,"x":2}})", j, why));
  EXPECT_FALSE(parse_json_strict(R"({"a":[{"k":1},{"k":2,"k":3}]})", j, why));
  EXPECT_FALSE(parse_json_strict(R"({"\u006fp":"ping","op":"estop"})", j, why));
  EXPECT_TRUE(parse_json_strict(R"({"a":{"k":1},"b":{"k":2}})", j, why)) << why;
}

TEST_F(Hardening, a_viewer_sending_deep_nesting_anywhere_gets_bad_json_and_the_server_lives) {
  start(with_tokens());
  RawSocket s(server_->port());
  ASSERT_TRUE(s.ok());
  s.send(std::string("{\"id\":1,\"op\":\"hello\",\"protocol\":1,\"token\":\"") + kViewer + "\"}\n");
  ASSERT_EQ(parse(s.read_line())["role"], "viewer");
  const std::string deep_array = std::string(50000, '[') + std::string(50000, ']');
  const std::string deep_object = [] {
    std::string o;
    for (int i = 0; i < 40000; ++i) {
      o += "{\"a\":";
    }
    return o + "0" + std::string(40000, '}');
  }();
  int id = 2;
  for (const std::string& payload : {deep_array, deep_object}) {
    for (const char* op : {"subscribe", "var.read", "trace.start", "program.chunk", "nosuch"}) {
      const std::string line = "{\"id\":" + std::to_string(id) + ",\"op\":\"" + op +
                               "\",\"topics\":" + payload + ",\"names\":" + payload + "}\n";
      s.send(line);
      const std::string reply = s.read_line();
      ASSERT_FALSE(reply.empty()) << op << ": no reply (server gone?)";
      EXPECT_LT(reply.size(), 512u) << "the client's JSON is never echoed back";
      EXPECT_EQ(parse(reply)["error"]["code"], "bad_json") << reply;
      ++id;
    }
  }
  // A well-formed but unknown topic is named, briefly, and not re-serialised.
  s.send("{\"id\":99,\"op\":\"subscribe\",\"topics\":[" + std::string(30, '[') +
         std::string(30, ']') + "]}\n");
  const std::string r = s.read_line();
  EXPECT_EQ(parse(r)["error"]["code"], "bad_request") << r;
  EXPECT_EQ(r.find("[[["), std::string::npos) << r;
  Client other;
  ASSERT_EQ(other.connect(client_opts(kOp)), Role::kOperator);
  EXPECT_TRUE(other.request("ping"));
}

TEST_F(Hardening, a_repeated_op_key_is_bad_json_and_does_nothing) {
  start();
  RawSocket s(server_->port());
  s.send("{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n");
  ASSERT_EQ(parse(s.read_line())["role"], "operator");
  for (const char* line :
       {R"({"id":2,"op":"ping","op":"estop"})", R"({"id":3,"op":"estop","id":4})",
        R"({"id":5,"op":"var.force","name":"chain.g.k","name":"io.ao0","value":1})"}) {
    s.send(std::string(line) + "\n");
    EXPECT_EQ(parse(s.read_line())["error"]["code"], "bad_json") << line;
  }
  EXPECT_EQ(rt_->machine().state(), rt::MachineState::kReady) << "nothing was e-stopped";
  EXPECT_TRUE(rt_->variables().forced().empty());
}

// ---- 2. broadcasts survive sessions closing under them ------------------------------------

TEST_F(Hardening, stalled_trace_status_and_alarm_subscribers_are_dropped_without_harm) {
  ServerOptions o;
  o.queue_limit = 16;
  o.queue_bytes = 64 * 1024;
  o.stall_timeout = 200ms;
  o.send_buffer_bytes = 4096;
  start(o);
  // Several stalled subscribers of every kind, so a broadcast loop closes one while others
  // follow it in the registry.
  std::vector<std::unique_ptr<RawSocket>> stalled;
  for (int i = 0; i < 6; ++i) {
    auto s = std::make_unique<RawSocket>(server_->port(), /*rcvbuf=*/1024);
    ASSERT_TRUE(s->ok());
    s->send("{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n");
    ASSERT_FALSE(s->read_line().empty());
    s->send(
        "{\"id\":2,\"op\":\"subscribe\",\"topics\":[\"status\",\"alarm\",\"progress\"],"
        "\"rate_hz\":100}\n"
        "{\"id\":3,\"op\":\"trace.start\",\"vars\":[\"io.ai0\",\"io.ao0\",\"chain.g.out\"]}\n");
    stalled.push_back(std::move(s));
  }
  ASSERT_TRUE(eventually([&] { return server_->stats().slow_disconnects >= 6; }, 20s))
      << server_->stats().slow_disconnects;
  Client c;
  ASSERT_EQ(c.connect(client_opts()), Role::kOperator);
  EXPECT_TRUE(c.request("ping"));
  // The dropped sessions are closed by posted tasks: wait for the count, not for a time.
  EXPECT_TRUE(eventually([&] { return server_->stats().sessions_open == 1u; }, 10s))
      << server_->stats().sessions_open;
}

// ---- 5. memory: the outgoing queue is bounded in bytes, replies are never lost ------------

TEST_F(Hardening, pipelined_requests_whose_replies_are_not_read_are_bounded_in_bytes) {
  ServerOptions o;
  o.queue_bytes = 64 * 1024;
  o.send_buffer_bytes = 4096;
  start(o);
  RawSocket s(server_->port(), /*rcvbuf=*/2048);
  s.send("{\"id\":0,\"op\":\"hello\",\"protocol\":1}\n");
  ASSERT_FALSE(s.read_line().empty());
  // var.list replies are large: thousands pipelined would be megabytes queued per session.
  const int kRequests = 3000;
  std::string all;
  for (int i = 1; i <= kRequests; ++i) {
    all += "{\"id\":" + std::to_string(i) + ",\"op\":\"var.list\"}\n";
  }
  std::thread writer([&] { s.send(all); });  // blocks while the server does not read
  // Every reply arrives, in order, once the client reads; none is dropped.
  std::size_t largest = 0;
  for (int next = 1; next <= kRequests; ++next) {
    const std::string line = s.read_line(10s);
    ASSERT_FALSE(line.empty()) << "reply " << next << " lost";
    largest = std::max(largest, line.size() + 1);
    const Json r = parse(line);
    if (r["id"] != next) {
      writer.detach();
      FAIL() << "expected reply " << next << ", got " << line.substr(0, 200);
    }
  }
  writer.join();
  EXPECT_GT(largest * kRequests, 8 * o.queue_bytes) << "the test must be able to overflow";
  EXPECT_LE(server_->stats().queue_bytes_peak, o.queue_bytes + largest);
}

TEST_F(Hardening, trace_start_traces_a_repeated_name_once) {
  start();
  Client c;
  c.connect(client_opts());
  std::vector<std::string> vars(500, "io.ai0");
  vars.push_back("chain.g.out");
  const Reply r = c.trace_start(vars);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(r.body["vars"], Json::array({"io.ai0", "chain.g.out"}));
}

// ---- 6. out of descriptors: accept backs off instead of spinning ------------------------------

TEST_F(Hardening, running_out_of_descriptors_backs_off_and_recovers) {
  start();
  // The runtime must be past its start-up (which opens descriptors) before the limit drops.
  ASSERT_TRUE(eventually([&] { return rt_->tasks().front()->cycles() > 10; }));
  // Connections come from another process, so only the server's accept() runs out.
  edm::apps::SpawnOptions piped;
  piped.in = edm::apps::Stream::kPipe;
  piped.out = edm::apps::Stream::kInherit;
  edm::apps::Process clients(
      {"python3", "-c",
       "import socket,sys; sys.stdin.readline(); s=[socket.create_connection(('127.0.0.1'," +
           std::to_string(server_->port()) + ")) for _ in range(20)]; sys.stdin.read()"},
      piped);
  ASSERT_TRUE(clients.started()) << clients.error();
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &old), 0);
  // New descriptors take the lowest free number, and the limit caps numbers: capping at the
  // lowest free one leaves none.
  const int lowest_free = ::dup(0);
  ASSERT_GE(lowest_free, 0);
  ::close(lowest_free);
  rlimit low = old;
  low.rlim_cur = static_cast<rlim_t>(lowest_free);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &low), 0);
  clients.write_input("go\n");
  const auto first_error_by = std::chrono::steady_clock::now();
  const bool errors = eventually([&] { return server_->stats().accept_errors >= 6; });
  const auto sixth = std::chrono::steady_clock::now();
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &old), 0);
  ASSERT_TRUE(errors) << "accept never failed (" << server_->stats().accept_errors << ")";
  // Backing off from 10 ms, doubling: six failures take at least 10+20+40+80+160 ms.
  EXPECT_GE(sixth - first_error_by, 310ms - 20ms);
  // With descriptors again, the waiting connections are accepted and new clients served.
  Client c;
  ASSERT_EQ(c.connect(client_opts()), Role::kOperator);
  EXPECT_TRUE(c.request("ping"));
  clients.close_input();  // python's sys.stdin.read() returns: it exits
  EXPECT_EQ(clients.wait(10s), 0);
}

// ---- 7. unauthenticated connections: a deadline and a cap of their own -------------------

TEST_F(Hardening, silent_sockets_never_lock_the_operator_out) {
  ServerOptions o = with_tokens();
  o.max_sessions = 2;
  o.max_pending = 8;
  o.hello_timeout = 500ms;
  start(o);
  std::vector<std::unique_ptr<RawSocket>> silent;
  for (int i = 0; i < 40; ++i) {  // far more than every cap
    silent.push_back(std::make_unique<RawSocket>(server_->port()));
  }
  // A viewer fills what viewers may have; the operator still gets in, at once.
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts(kViewer)), Role::kViewer);
  Client second_viewer;
  EXPECT_THROW(second_viewer.connect(client_opts(kViewer)), ClientError)
      << "one slot is kept for an operator";
  Client op;
  ASSERT_EQ(op.connect(client_opts(kOp)), Role::kOperator);
  EXPECT_LE(server_->stats().sessions_pending, 8u);
  EXPECT_GE(server_->stats().pending_evicted, 30u);
  // The silent ones that were not evicted are closed at the hello deadline.
  for (auto& s : silent) {
    EXPECT_TRUE(s->closed_within(5s));
  }
  EXPECT_GE(server_->stats().hello_timeouts, 1u);
  EXPECT_TRUE(op.request("ping"));
}

TEST_F(Hardening, a_blank_line_keeps_a_session_alive_but_not_past_the_hello_deadline) {
  ServerOptions o;
  o.read_timeout = 400ms;
  o.hello_timeout = 400ms;
  start(o);
  RawSocket pre(server_->port());
  RawSocket s(server_->port());
  s.send("{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n");
  ASSERT_FALSE(s.read_line().empty());
  // 2 s of keep-alives, one every 100 ms: five read timeouts' worth.
  for (int i = 0; i < 20; ++i) {
    s.send("\n");
    pre.send("\n");
    EXPECT_FALSE(s.closed_within(100ms)) << "closed after " << i * 100 << " ms";
  }
  EXPECT_TRUE(pre.closed_within(1s)) << "keep-alives do not stand in for a hello";
  s.send("{\"id\":2,\"op\":\"ping\"}\n");
  EXPECT_EQ(parse(s.read_line())["pong"], true);
  EXPECT_TRUE(s.closed_within(3s)) << "silence still times out";
}

// ---- 8. token guessing ------------------------------------------------------------------------

TEST(HelloThrottleUnit, delays_double_per_failure_up_to_the_cap_and_are_forgotten) {
  HelloThrottle t(/*max_keys=*/3);
  const auto t0 = HelloThrottle::Clock::time_point{} + std::chrono::hours(1);
  EXPECT_EQ(t.admit_at("a", "", t0), t0);
  std::chrono::milliseconds expect = HelloThrottle::kBaseDelay;
  auto now = t0;
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(t.on_failure("a", "", now), std::min(expect, HelloThrottle::kMaxDelay));
    EXPECT_EQ(t.admit_at("a", "", now), now + std::min(expect, HelloThrottle::kMaxDelay));
    now = t.admit_at("a", "", now);
    expect *= 2;
  }
  EXPECT_EQ(t.admit_at("b", "", now), now) << "other addresses are not slowed";
  t.on_failure("a", "", now);
  const auto later = now + HelloThrottle::kForgetAfter + 1ms;
  EXPECT_EQ(t.admit_at("a", "", later), later);
  for (const char* p : {"p", "q", "r", "s"}) {
    t.on_failure(p, "", now);
  }
  EXPECT_LE(t.keys(), 3u);
  EXPECT_LE(t.addresses(), 3u);
}

TEST_F(Hardening, wrong_hellos_are_throttled_logged_and_a_right_token_still_gets_in) {
  start(with_tokens());
  // 30 guesses on 30 parallel connections, as fast as the client can send them.
  const auto sent_at = std::chrono::steady_clock::now();  // before the first failure
  std::vector<std::unique_ptr<RawSocket>> guessers;
  for (int i = 0; i < 30; ++i) {
    guessers.push_back(std::make_unique<RawSocket>(server_->port()));
    guessers.back()->send("{\"id\":1,\"op\":\"hello\",\"protocol\":1,\"token\":\"guess-" +
                          std::to_string(i) + "-xxxxxxxxxxxx\"}\n");
  }
  // Each refusal comes no sooner than the throttle allows: 0, 250, 500, 1000 ms apart.
  std::vector<std::chrono::steady_clock::time_point> refused;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  std::vector<bool> answered(guessers.size(), false);
  while (refused.size() < 4 && std::chrono::steady_clock::now() < deadline) {
    for (std::size_t i = 0; i < guessers.size(); ++i) {
      if (!answered[i] && !guessers[i]->read_line(1ms).empty()) {
        answered[i] = true;
        refused.push_back(std::chrono::steady_clock::now());
      }
    }
  }
  ASSERT_EQ(refused.size(), 4u);
  // The fourth is evaluated at least 250 + 500 + 1000 ms after the first failure, which came
  // after sent_at (a lower bound that no slowness of this reading loop can break).
  EXPECT_GE(refused[3] - sent_at, 250ms + 500ms + 1000ms);
  EXPECT_GE(server_->stats().hello_failures, 4u);
  guessers.clear();
  Client op;
  ASSERT_EQ(op.connect(client_opts(kOp)), Role::kOperator) << "delayed, never refused";
}

TEST(BridgeAuthHardening, short_tokens_are_refused) {
  edm::test::TempDir dir{"edm-tok"};
  const std::string f = dir.file("t");
  for (const char* tok : {"x", "secret", "fifteen-chars!!"}) {
    write_token(f, tok, 0600);
    EXPECT_THROW(load_tokens(f, ""), BridgeError) << tok;
  }
  write_token(f, "sixteen-chars!!!", 0600);
  EXPECT_NO_THROW(load_tokens(f, ""));
}

// ---- 9. the audit trail -----------------------------------------------------------------------

TEST_F(Hardening, state_changing_requests_are_audited_with_session_role_and_peer) {
  ServerOptions o = with_tokens();
  o.audit_file = dir_.file("audit.log");
  start(o);
  Client op;
  ASSERT_EQ(op.connect(client_opts(kOp)), Role::kOperator);
  Client viewer;
  ASSERT_EQ(viewer.connect(client_opts(kViewer)), Role::kViewer);
  ASSERT_TRUE(op.request("estop"));
  ASSERT_TRUE(op.request("reset"));
  ASSERT_TRUE(op.request("var.write", {{"name", "chain.g.k"}, {"value", 2.5}}));
  ASSERT_TRUE(op.request("var.force", {{"name", "io.ao0"}, {"value", 1}}));
  ASSERT_TRUE(op.request("var.unforce", {{"name", "io.ao0"}}));
  EXPECT_FALSE(op.request("cycle.resume"));
  EXPECT_FALSE(viewer.request("estop"));
  EXPECT_TRUE(viewer.request("status"));
  std::ifstream in(o.audit_file);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) {
    lines.push_back(l);
  }
  ASSERT_EQ(lines.size(), 7u) << "one entry per state-changing request, none for status";
  const auto has = [&](std::size_t i, const std::string& what) {
    EXPECT_NE(lines[i].find(what), std::string::npos) << lines[i] << " lacks " << what;
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    has(i, "peer=127.0.0.1:");
    has(i, "session=");
  }
  has(0, "role=operator");
  has(0, "op=estop -> ok");
  has(1, "op=reset -> ok");
  has(2, "op=var.write name='chain.g.k' value=2.5 -> ok");
  has(3, "op=var.force name='io.ao0' value=1 -> ok");
  has(5, "op=cycle.resume -> invalid_state");
  has(6, "role=viewer");
  has(6, "op=estop -> forbidden");
}

// ---- 4. a repeating alarm: one event, then counted, and the count is visible ----------------

TEST_F(Hardening, a_persisting_alarm_is_one_event_and_its_repeats_are_counted_in_tasks_stats) {
  start();
  EventSink sink;
  Client c;
  ASSERT_EQ(connect_with_events(c, sink), Role::kOperator);
  ASSERT_TRUE(c.subscribe({"alarm"}));
  const rt::Alarm a = warning_alarm("test.raiser", "persisting");
  for (int i = 0; i < 500; ++i) {
    rt_->machine().raise(a);
  }
  ASSERT_EQ(sink.wait_for("alarm", 1).size(), 1u);
  const Reply r = c.request("tasks.stats");
  ASSERT_TRUE(r) << r.message;
  const Json& alarms = r.body["alarms"];
  ASSERT_EQ(alarms["active"].size(), 1u) << alarms;
  EXPECT_EQ(alarms["active"][0]["source"], "test.raiser");
  EXPECT_EQ(alarms["active"][0]["count"], 500);
  EXPECT_EQ(alarms["repeated"], 499);
  EXPECT_EQ(sink.wait_for("alarm", 2, 300ms).size(), 1u) << "the repeats sent no events";
}

// ---- the in-memory transport: the dispatcher without a socket (fuzzing uses it) ------------

TEST_F(Hardening, a_session_over_the_memory_transport_runs_the_real_dispatcher) {
  start();
  MemoryPeer peer(server_->io_context());
  server_->adopt(peer.transport());
  peer.send("{\"id\":1,\"op\":\"hello\",\"protocol\":1}\n{\"id\":2,\"op\":\"status\"}\n");
  ASSERT_TRUE(peer.wait_for("\"id\":2"));
  EXPECT_NE(peer.output().find("\"role\":\"operator\""), std::string::npos);
  peer.send("{\"id\":3,\"op\":\"nosuch\"}\n");
  ASSERT_TRUE(peer.wait_for("unknown_op"));
  peer.close_input();
  EXPECT_TRUE(peer.wait_closed());
  EXPECT_TRUE(eventually([&] { return server_->stats().sessions_open == 0; }));
}

}  // namespace
}  // namespace edm::bridge::test
