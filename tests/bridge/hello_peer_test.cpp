// hello's "peer" (issue 31, item 5, edmplc's side): a relaying HMI (edmhmi serve) names the end
// client, and the failed-hello throttle keys on (transport address, peer), so one browser's
// wrong tokens do not lock another out; an aggregate per transport address keeps a client that
// rotates `peer` to at most 64 failures a minute.
#include <gtest/gtest.h>

#include <deque>
#include <fstream>

#include "bridge_fixture.hpp"
#include "edm/bridge/hello_throttle.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;
using Clock = HelloThrottle::Clock;

Json parse_reply(const std::string& line) { return Json::parse(line, nullptr, false); }

std::string hello_line(const std::string& token, const Json& peer) {
  Json h = {{"id", 1}, {"op", "hello"}, {"protocol", 1}, {"token", token}};
  if (!peer.is_null()) h["peer"] = peer;
  return h.dump() + "\n";
}

TEST(HelloThrottlePeer, forty_failures_of_one_peer_do_not_delay_another) {
  HelloThrottle t;
  const std::string addr = "127.0.0.1";
  auto now = Clock::time_point{} + 1h;
  // Peer A guesses as fast as the throttle lets it, 40 times.
  for (int i = 0; i < 40; ++i) {
    now = std::max(now, t.admit_at(addr, "A", now));
    t.on_failure(addr, "A", now);
  }
  EXPECT_GT(t.admit_at(addr, "A", now), now) << "A itself is throttled";
  EXPECT_EQ(t.admit_at(addr, "B", now), now) << "B is not";
  EXPECT_EQ(t.admit_at(addr, "", now), now) << "nor the relay's own hello";
  EXPECT_EQ(t.admit_at("127.0.0.2", "A", now), now) << "nor A behind another relay";
}

TEST(HelloThrottlePeer, a_single_peer_never_reaches_the_aggregate) {
  HelloThrottle t;
  const std::string addr = "10.0.0.9";
  const auto t0 = Clock::time_point{} + 1h;
  auto now = t0;
  std::deque<Clock::time_point> window;
  std::size_t most = 0;
  while (now < t0 + 30min) {
    now = std::max(now, t.admit_at(addr, "one-browser", now));
    t.on_failure(addr, "one-browser", now);
    window.push_back(now);
    while (now - window.front() >= HelloThrottle::kForgetAfter) window.pop_front();
    most = std::max(most, window.size());
  }
  std::printf("one peer: at most %zu failures in any 60 s window\n", most);
  EXPECT_LE(most, 11u);  // 0, .25, .75, 1.75, 3.75, 7.75, 15.75 … s: then one per 10 s
  EXPECT_LT(most, HelloThrottle::kAggregateFailures);
}

TEST(HelloThrottlePeer, rotating_peers_meet_the_aggregate_bound) {
  HelloThrottle t(/*max_keys=*/256);
  const std::string addr = "10.0.0.7";
  const auto t0 = Clock::time_point{} + 1h;
  auto now = t0;
  std::deque<Clock::time_point> window;
  std::size_t most = 0;
  std::uint64_t guesses = 0;
  // A new peer for every guess, each guess as early as the throttle evaluates it, 10 minutes.
  for (int i = 0; now < t0 + 10min; ++i) {
    const std::string peer = "rot-" + std::to_string(i);
    now = std::max(now, t.admit_at(addr, peer, now));
    if (i == static_cast<int>(HelloThrottle::kAggregateFailures)) {
      EXPECT_EQ(now, t0 + HelloThrottle::kForgetAfter) << "the 65th waits for the first to age";
    }
    t.on_failure(addr, peer, now);
    ++guesses;
    window.push_back(now);
    while (now - window.front() >= HelloThrottle::kForgetAfter) window.pop_front();
    most = std::max(most, window.size());
  }
  std::printf("rotating peers: %llu guesses in 10 min, at most %zu in any 60 s\n",
              static_cast<unsigned long long>(guesses), most);
  EXPECT_LE(most, HelloThrottle::kAggregateFailures);
  EXPECT_LE(guesses, 11 * HelloThrottle::kAggregateFailures);
  EXPECT_LE(t.keys(), 256u) << "memory stays bounded while peers rotate";
}

class HelloPeer : public BridgeFixture {
 protected:
  ServerOptions with_tokens() {
    ServerOptions o;
    o.token_file = dir_.file("op.token");
    write_token(o.token_file, kOp, 0600);
    o.audit_file = dir_.file("audit.log");
    return o;
  }
  static constexpr const char* kOp = "operator-token-4f1c2a9b";
};

TEST_F(HelloPeer, forty_wrong_hellos_of_peer_a_leave_peer_b_admitted_at_once) {
  start(with_tokens());
  // 40 wrong-token log-ins of browser A relayed through one edmhmi, as fast as they go out.
  std::vector<std::unique_ptr<RawSocket>> a;
  for (int i = 0; i < 40; ++i) {
    a.push_back(std::make_unique<RawSocket>(server_->port()));
    a.back()->send(hello_line("wrong-token-" + std::to_string(i) + "-xxxxxxxx", "192.0.2.10"));
  }
  // Wait until A's throttle is at 2 s or more (four failures evaluated: 0, .25, .75, 1.75 s).
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (server_->stats().hello_failures < 4 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);  // polling the server's counter, with a deadline
  }
  ASSERT_GE(server_->stats().hello_failures, 4u);
  // Browser B, through the same edmhmi, with the right token: in at once.
  Client b;
  ClientOptions o = client_opts(kOp);
  o.peer = "192.0.2.20";
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(b.connect(o), Role::kOperator);
  const auto took = std::chrono::steady_clock::now() - t0;
  EXPECT_LT(took, 1s) << "B waited behind A's throttle";
  // B's requests are audited with the end client it came from.
  ASSERT_TRUE(b.request("estop"));
  std::ifstream in(dir_.file("audit.log"));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_NE(line.find(" via=\"192.0.2.20\" op=estop -> ok"), std::string::npos) << line;
  a.clear();
}

TEST_F(HelloPeer, a_client_rotating_peer_is_held_to_the_aggregate) {
  start(with_tokens());
  const auto n = static_cast<int>(HelloThrottle::kAggregateFailures);
  for (int i = 0; i < n; ++i) {
    RawSocket s(server_->port());
    s.send(hello_line("guess-" + std::to_string(i) + "-xxxxxxxxxxxx", "rot-" + std::to_string(i)));
    const Json r = parse_reply(s.read_line(5s));
    ASSERT_EQ(r["error"]["code"], "unauthorized") << i << ": each new peer is evaluated at once";
  }
  EXPECT_EQ(server_->stats().hello_failures, static_cast<std::uint64_t>(n));
  // The next one — a new peer again, even with the right token — waits for the window.
  RawSocket s(server_->port());
  s.send(hello_line(kOp, "rot-new"));
  EXPECT_EQ(s.read_line(700ms), "") << "answered before the aggregate allows";
  EXPECT_EQ(server_->stats().hello_failures, static_cast<std::uint64_t>(n));
}

TEST_F(HelloPeer, a_bad_peer_is_bad_request_and_guesses_nothing) {
  start(with_tokens());
  const std::vector<Json> bad = {Json(1),
                                 Json(""),
                                 Json(std::string(65, 'p')),
                                 Json("a\nb"),
                                 Json("tab\there"),
                                 Json("\xc3\xa9t\xc3\xa9"),
                                 Json::array({"x"}),
                                 Json(nullptr)};
  for (const Json& p : bad) {
    RawSocket s(server_->port());
    Json h = {{"id", 1}, {"op", "hello"}, {"protocol", 1}, {"token", kOp}, {"peer", p}};
    s.send(h.dump() + "\n");
    const Json r = parse_reply(s.read_line());
    EXPECT_EQ(r["error"]["code"], "bad_request") << p.dump() << " → " << r;
    EXPECT_TRUE(s.closed_within(3s)) << p.dump();
  }
  EXPECT_EQ(server_->stats().hello_failures, 0u) << "no token was evaluated";
  // The longest valid one, with every printable character class, is accepted.
  Client c;
  ClientOptions o = client_opts(kOp);
  o.peer = std::string(62, 'q') + "\"\\";
  EXPECT_EQ(c.connect(o), Role::kOperator);
}

TEST(HelloParams, the_encoder_sends_peer_only_when_given) {
  EXPECT_EQ(hello_params("tok"), (Json{{"protocol", kProtocolVersion}, {"token", "tok"}}));
  EXPECT_EQ(hello_params("tok", "[2001:db8::1]:443")["peer"], "[2001:db8::1]:443");
  EXPECT_TRUE(valid_hello_peer(std::string(kMaxHelloPeerChars, '~')));
  EXPECT_FALSE(valid_hello_peer(std::string(kMaxHelloPeerChars + 1, '~')));
  EXPECT_FALSE(valid_hello_peer(""));
  EXPECT_FALSE(valid_hello_peer("a\x7f"));
}

}  // namespace
}  // namespace edm::bridge::test
