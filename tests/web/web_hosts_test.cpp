// The Host and Origin allow-list of `edmhmi serve` (hmi/include/edm/hmi/web_hosts.hpp, issue 31
// item 1): DNS rebinding refused, loopback names and the listen address served, configured
// names served, Origin parsed and compared, never only against Host as a string.
#include "edm/hmi/web_hosts.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace edm::hmi::test {
namespace {

namespace ip = boost::asio::ip;

const ip::address kLoopback = ip::make_address("127.0.0.1");

TEST(WebHosts, host_port_parsing) {
  const auto a = parse_host_port("Evil.Example.:8080");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->host, "evil.example");
  EXPECT_EQ(a->port, 8080);
  const auto v6 = parse_host_port("[::1]:80");
  ASSERT_TRUE(v6);
  EXPECT_EQ(v6->host, "::1");
  EXPECT_TRUE(v6->ipv6);
  EXPECT_FALSE(parse_host_port("localhost")->port);
  for (const char* bad :
       {"", ":80", "a:", "a:0", "a:65536", "a:8x", "a:80:81", "user@host", "host/path", "[::1",
        "[::1]x", "[zz]", "[fe80::1%eth0]", "a b", ".", "..x", "a\r\nX: y", "h\xc3\xa9"}) {
    EXPECT_FALSE(parse_host_port(bad)) << bad;
  }
}

TEST(WebHosts, origin_parsing) {
  const auto o = parse_origin("HTTP://LocalHost:8080");
  ASSERT_TRUE(o);
  EXPECT_EQ(o->scheme, "http");
  EXPECT_EQ(o->authority.host, "localhost");
  EXPECT_EQ(o->authority.port, 8080);
  EXPECT_EQ(parse_origin("https://hmi.plant")->authority.port, 443);
  EXPECT_EQ(parse_origin("http://hmi.plant")->authority.port, 80);
  for (const char* bad : {"null", "", "file://", "ws://localhost", "http://", "http://a/",
                          "http://a:80/x", "http://u@a", "javascript:alert(1)", "localhost:80"}) {
    EXPECT_FALSE(parse_origin(bad)) << bad;
  }
}

// The attack of issue 31: a page at evil.example whose name now resolves to 127.0.0.1.
TEST(WebHosts, dns_rebinding_is_refused) {
  const HostAllowList hosts(kLoopback, {}, false);
  EXPECT_FALSE(hosts.allows_host("evil.example:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_host("evil.example", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("http://evil.example:8080", "evil.example:8080", kLoopback));
  // A name that only looks local is not.
  for (const char* h : {"localhost.evil.example", "127.0.0.1.evil.example", "evil.localhost",
                        "0x7f000001", "2130706433", "127.1"}) {
    EXPECT_FALSE(hosts.allows_host(h, kLoopback)) << h;
  }
}

TEST(WebHosts, loopback_names_and_the_listen_address_with_any_port) {
  const HostAllowList hosts(ip::make_address("10.0.0.9"), {}, false);
  for (const char* h :
       {"localhost", "LOCALHOST:9000", "localhost.:8080", "127.0.0.1", "127.0.0.1:8080",
        "127.8.9.10:1", "[::1]:8080", "[::ffff:127.0.0.1]", "10.0.0.9:8443", "10.0.0.9"}) {
    EXPECT_TRUE(hosts.allows_host(h, kLoopback)) << h;
  }
  EXPECT_FALSE(hosts.allows_host("10.0.0.8:8080", kLoopback));
  // Listening on every address: the address the connection came in on is the station's own.
  const HostAllowList any(ip::make_address("0.0.0.0"), {}, false);
  const ip::address lan = ip::make_address("192.168.7.20");
  EXPECT_TRUE(any.allows_host("192.168.7.20:8080", lan));
  EXPECT_FALSE(any.allows_host("192.168.7.21:8080", lan));
  EXPECT_TRUE(
      any.allows_host("[::ffff:192.168.7.20]:8080", ip::make_address("::ffff:192.168.7.20")));
}

TEST(WebHosts, configured_names) {
  const HostAllowList hosts(kLoopback, {"HMI.plant", "cell7.plant:8443"}, true);
  EXPECT_TRUE(hosts.allows_host("hmi.plant", kLoopback));
  EXPECT_TRUE(hosts.allows_host("hmi.plant:9999", kLoopback));
  EXPECT_TRUE(hosts.allows_host("cell7.plant:8443", kLoopback));
  EXPECT_FALSE(hosts.allows_host("cell7.plant:8444", kLoopback));
  EXPECT_FALSE(hosts.allows_host("cell7.plant", kLoopback)) << "443 is not 8443";
  EXPECT_FALSE(hosts.allows_host("cell8.plant:8443", kLoopback));
  // A proxy in front may change scheme and port: a configured name's origin is enough.
  EXPECT_TRUE(hosts.allows_origin("http://hmi.plant", "127.0.0.1:8443", kLoopback));
  EXPECT_TRUE(hosts.allows_origin("https://cell7.plant:8443", "cell7.plant:8443", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("https://cell7.plant", "cell7.plant:8443", kLoopback));
  EXPECT_THROW(HostAllowList(kLoopback, {"bad name"}, false), std::invalid_argument);
  EXPECT_THROW(HostAllowList(kLoopback, {"a:0"}, false), std::invalid_argument);
}

TEST(WebHosts, origin_must_be_the_requests_own_and_allowed) {
  const HostAllowList hosts(kLoopback, {}, false);
  EXPECT_TRUE(hosts.allows_origin("http://127.0.0.1:8080", "127.0.0.1:8080", kLoopback));
  EXPECT_TRUE(hosts.allows_origin("http://localhost:9000", "localhost:9000", kLoopback));
  EXPECT_TRUE(hosts.allows_origin("http://[::1]:8080", "[::1]:8080", kLoopback));
  EXPECT_TRUE(hosts.allows_origin("http://localhost", "localhost:80", kLoopback));
  // Another local page (another port, another loopback name, another scheme) is not ours.
  EXPECT_FALSE(hosts.allows_origin("http://localhost:3000", "localhost:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("http://127.0.0.1:8080", "localhost:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("https://127.0.0.1:8080", "127.0.0.1:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("null", "127.0.0.1:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("", "127.0.0.1:8080", kLoopback));
  EXPECT_FALSE(hosts.allows_origin("http://127.0.0.1:8080", "", kLoopback));
  const HostAllowList tls(kLoopback, {}, true);
  EXPECT_TRUE(tls.allows_origin("https://127.0.0.1:8443", "127.0.0.1:8443", kLoopback));
  EXPECT_TRUE(tls.allows_origin("https://localhost", "localhost", kLoopback));
  EXPECT_FALSE(tls.allows_origin("http://127.0.0.1:8443", "127.0.0.1:8443", kLoopback));
}

}  // namespace
}  // namespace edm::hmi::test
