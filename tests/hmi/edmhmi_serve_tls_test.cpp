// `edmhmi serve` over HTTPS (docs/web.md "HTTPS"): the page and the WebSocket to a client that
// trusts the test's self-signed certificate (and not to one that does not), the refusal of plain
// HTTP off loopback when the bridge uses TLS, the loopback warning, and the located errors for
// certificate and key files that cannot be used. The refusals end before edmplc is contacted.
#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <filesystem>
#include <fstream>
#include <regex>

#include "process_fixture.hpp"
#include "support/self_signed.hpp"

namespace edm::hmi::test {
namespace {

namespace asio = boost::asio;
namespace ssl = asio::ssl;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using TlsStream = beast::ssl_stream<beast::tcp_stream>;

constexpr const char* kPage = "<!doctype html><title>edm</title>served over tls";

class EdmhmiServeTlsTest : public EdmhmiProcessTest {
 protected:
  void SetUp() override {
    ASSERT_FALSE(edm::test::make_self_signed(key_, cert_, "edm-web").empty())
        << "openssl could not make a certificate";
    std::filesystem::create_directories(root_);
    std::ofstream(root_ + "/index.html") << kPage;
  }

  /// Starts `edmhmi serve` on a loopback port the system picks; returns that port (0 on failure).
  int serve(const std::vector<std::string>& extra) {
    std::vector<std::string> args{"serve", "--listen", "127.0.0.1:0", "--web-root", root_};
    args.insert(args.end(), extra.begin(), extra.end());
    Proc& p = spawn(args);
    static const std::regex kListening(R"(listening on https://127\.0\.0\.1:([0-9]+)/)");
    std::smatch m;
    std::string out;
    poll_until(
        [&] {
          out = p.out();
          return std::regex_search(out, m, kListening) || p.poll().has_value();
        },
        20s);
    if (m.empty()) ADD_FAILURE() << "edmhmi serve did not listen\n" << out << p.err();
    return m.empty() ? 0 : std::stoi(m[1].str());
  }

  /// A TLS client stream to 127.0.0.1:`port` that trusts only the test certificate.
  TlsStream connect_tls(int port) {
    client_ctx_.set_verify_mode(ssl::verify_peer);
    client_ctx_.load_verify_file(cert_);
    TlsStream stream(ioc_, client_ctx_);
    stream.set_verify_callback(ssl::host_name_verification("127.0.0.1"));
    beast::get_lowest_layer(stream).expires_after(10s);
    beast::get_lowest_layer(stream).connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<std::uint16_t>(port)));
    stream.handshake(ssl::stream_base::client);
    return stream;
  }

  std::string cert_ = dir_.file("web.crt");
  std::string key_ = dir_.file("web.key");
  std::string root_ = dir_.file("page");
  asio::io_context ioc_;
  ssl::context client_ctx_{ssl::context::tls_client};
};

/// The arguments `[global...] serve [serve...]`: the connection flags go before the command.
std::vector<std::string> with(std::vector<std::string> global, std::vector<std::string> serve) {
  global.push_back("serve");
  global.insert(global.end(), serve.begin(), serve.end());
  return global;
}

TEST_F(EdmhmiServeTlsTest, TheHttpsPageReachesAClientThatTrustsTheCertificate) {
  start_plc();
  const int port = serve({"--tls-cert", cert_, "--tls-key", key_});
  ASSERT_NE(port, 0);
  TlsStream stream = connect_tls(port);
  http::request<http::empty_body> req{http::verb::get, "/", 11};
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(res.body(), kPage);
  EXPECT_FALSE(res["Content-Security-Policy"].empty());
}

TEST_F(EdmhmiServeTlsTest, AClientThatDoesNotTrustTheCertificateFailsTheHandshake) {
  start_plc();
  const int port = serve({"--tls-cert", cert_, "--tls-key", key_});
  ASSERT_NE(port, 0);
  ssl::context untrusting{ssl::context::tls_client};
  untrusting.set_default_verify_paths();
  untrusting.set_verify_mode(ssl::verify_peer);
  TlsStream stream(ioc_, untrusting);
  beast::get_lowest_layer(stream).expires_after(10s);
  beast::get_lowest_layer(stream).connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<std::uint16_t>(port)));
  beast::error_code ec;
  stream.handshake(ssl::stream_base::client, ec);
  EXPECT_TRUE(ec) << "a self-signed certificate was accepted without being trusted";
}

TEST_F(EdmhmiServeTlsTest, TheWebSocketUpgradesOverTlsAndWelcomesALogIn) {
  start_plc();
  const int port = serve({"--tls-cert", cert_, "--tls-key", key_});
  ASSERT_NE(port, 0);
  beast::websocket::stream<TlsStream> ws(connect_tls(port));
  beast::get_lowest_layer(ws).expires_never();
  ws.set_option(beast::websocket::stream_base::timeout::suggested(beast::role_type::client));
  // A browser's upgrade says its origin (one without is refused, docs/security.md).
  const std::string origin = "https://127.0.0.1:" + std::to_string(port);
  ws.set_option(beast::websocket::stream_base::decorator(
      [origin](beast::websocket::request_type& req) { req.set(http::field::origin, origin); }));
  ws.handshake("127.0.0.1:" + std::to_string(port), "/ws");
  ws.text(true);
  ws.write(asio::buffer(std::string(R"({"t":"login","token":"any"})")));
  // First the bridge's state ({"t":"bridge"}), then the welcome.
  std::string first;
  for (int i = 0; i < 3 && first.find(R"("t":"welcome")") == std::string::npos; ++i) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    first = beast::buffers_to_string(buffer.data());
  }
  EXPECT_NE(first.find(R"("t":"welcome")"), std::string::npos) << first.substr(0, 200);
  ws.close(beast::websocket::close_code::normal);
}

TEST_F(EdmhmiServeTlsTest, PlainHttpOffLoopbackIsRefusedWhenTheBridgeUsesTls) {
  const std::string pin = "AB:CD:EF";
  const Outcome o =
      edmhmi(with({"--tls-fingerprint", pin}, {"--web-root", root_, "--listen", "0.0.0.0:0"}), {},
             /*flags=*/false);
  EXPECT_EQ(o.code, 2) << o.out << o.err;
  EXPECT_NE(o.err.find("the bridge uses TLS but the page on 0.0.0.0:0 would be plain HTTP"),
            std::string::npos)
      << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  // --insecure-listen is not enough when the bridge is TLS; from the environment too.
  const Outcome env =
      edmhmi({"serve", "--web-root", root_, "--listen", "0.0.0.0:0", "--insecure-listen"},
             {{"EDM_TLS_FINGERPRINT", pin}}, /*flags=*/false);
  EXPECT_EQ(env.code, 2) << env.out << env.err;
  EXPECT_NE(env.err.find("--insecure-http"), std::string::npos) << env.err;
}

TEST_F(EdmhmiServeTlsTest, PlainHttpOnLoopbackWithATlsBridgeOnlyWarns) {
  // Nothing listens on the bridge port: after the warning, serve keeps serving and waits for
  // edmplc (issue 31, startup) until the helper's deadline stops it; never exit 2.
  const Outcome o =
      edmhmi(with({"--port", std::to_string(free_port()), "--tls-fingerprint", "AB:CD:EF"},
                  {"--web-root", root_, "--listen", "127.0.0.1:0"}),
             {}, /*flags=*/false);
  EXPECT_NE(o.code, 2) << o.out << o.err;
  EXPECT_NE(o.err.find("waiting for edmplc at 127.0.0.1:"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("warning: the bridge uses TLS but the page is plain HTTP on loopback"),
            std::string::npos)
      << o.err;
}

TEST_F(EdmhmiServeTlsTest, UnusableCertificateOrKeyFilesAreNamedAndExitTwo) {
  const std::string garbage = dir_.file("garbage.pem");
  std::ofstream(garbage) << "not a certificate\n";
  const std::string other_key = dir_.file("other.key");
  const std::string other_cert = dir_.file("other.crt");
  ASSERT_FALSE(edm::test::make_self_signed(other_key, other_cert, "other").empty());
  const std::string missing = dir_.file("missing.crt");
  struct Case {
    std::vector<std::string> args;
    Env env;
    std::string error;
  };
  const std::vector<Case> cases{
      {{"--tls-cert", missing, "--tls-key", key_}, {}, "--tls-cert " + missing + ": no such file"},
      {{"--tls-cert", root_, "--tls-key", key_},
       {},
       "--tls-cert " + root_ + ": not a regular file"},
      {{"--tls-cert", garbage, "--tls-key", key_}, {}, "--tls-cert " + garbage + ": not a PEM"},
      {{"--tls-cert", cert_, "--tls-key", garbage}, {}, "--tls-key " + garbage + ": not a PEM"},
      {{"--tls-cert", cert_, "--tls-key", other_key},
       {},
       "--tls-key " + other_key + ": does not belong to the certificate in " + cert_},
      {{},
       {{"EDM_WEB_TLS_CERT", cert_}, {"EDM_WEB_TLS_KEY", missing}},
       "--tls-key " + missing + ": no such file"},
      {{"--tls-cert", cert_}, {}, "--tls-cert needs --tls-key"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"serve", "--web-root", root_};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const Outcome o = edmhmi(args, c.env, /*flags=*/false);
    EXPECT_EQ(o.code, 2) << c.error << "\n" << o.out << o.err;
    EXPECT_NE(o.err.find(c.error), std::string::npos) << o.err;
    EXPECT_EQ(o.err.find("terminate"), std::string::npos) << o.err;
  }
}

}  // namespace
}  // namespace edm::hmi::test
