// edmhmi serve [--listen HOST:PORT] [--web-root DIR] — the operator's screen in a browser
// (docs/web.md): serves the built page and a WebSocket, owns one bridge session to edmplc and the
// job, relays commands for logged-in browsers.
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/signal_set.hpp>
#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "edm/hmi/web_http.hpp"
#include "edm/hmi/web_hub.hpp"

namespace edmhmi {

namespace {

bool parse_listen(std::string_view text, boost::asio::ip::tcp::endpoint& out, std::string& why) {
  const auto colon = text.rfind(':');
  if (colon == std::string_view::npos) {
    why = "--listen wants HOST:PORT";
    return false;
  }
  boost::system::error_code ec;
  const auto address = boost::asio::ip::make_address(std::string(text.substr(0, colon)), ec);
  if (ec) {
    why = "--listen: '" + std::string(text.substr(0, colon)) + "' is not an IP address";
    return false;
  }
  const std::string_view port = text.substr(colon + 1);
  unsigned p = 0;
  for (char c : port) {
    if (c < '0' || c > '9' || p > 65535) {
      why = "--listen: bad port";
      return false;
    }
    p = p * 10 + static_cast<unsigned>(c - '0');
  }
  if (port.empty() || p > 65535) {
    why = "--listen: bad port";
    return false;
  }
  out = {address, static_cast<std::uint16_t>(p)};
  return true;
}

}  // namespace

int cmd_serve(const ServeArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const std::string& listen = args.listen;
  const std::string& web_root = args.web_root;
  const bool insecure = args.insecure;
  boost::asio::ip::tcp::endpoint endpoint;
  std::string why;
  if (!parse_listen(listen, endpoint, why)) return usage(why);
  if (!endpoint.address().is_loopback() && !insecure) {
    std::fprintf(stderr,
                 "edmhmi serve: %s is not a loopback address: the page speaks plain HTTP and "
                 "tokens would cross the network in clear. Use an SSH tunnel or a TLS proxy, or "
                 "--insecure-listen on a network you trust (docs/web.md).\n",
                 listen.c_str());
    return kExitBadInput;
  }
  if (!std::filesystem::is_regular_file(std::filesystem::path(web_root) / "index.html")) {
    std::fprintf(stderr,
                 "edmhmi serve: %s/index.html missing: build the page (./edm build, or "
                 "cmake --build build --target edm_web)\n",
                 web_root.c_str());
    return kExitBadInput;
  }

  edm::bridge::Client client;
  if (!connect(client, settings, /*auto_reconnect=*/true)) return kExitFailure;
  boost::asio::io_context ioc;
  edm::hmi::WebHub hub(ioc, client, settings);
  try {
    hub.start();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edmhmi serve: %s\n", e.what());
    return kExitFailure;
  }
  std::shared_ptr<edm::hmi::WebListener> listener;
  try {
    listener = std::make_shared<edm::hmi::WebListener>(ioc, endpoint, web_root, hub);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edmhmi serve: cannot listen on %s: %s\n", listen.c_str(), e.what());
    return kExitFailure;
  }
  listener->run();
  boost::asio::signal_set signals(ioc, SIGINT, SIGTERM);
  signals.async_wait([&ioc](boost::system::error_code, int) { ioc.stop(); });
  const auto ep = listener->local_endpoint();
  std::printf("edmhmi serve: listening on http://%s:%u/ (edmplc at %s:%u as %s, page %s)\n",
              ep.address().to_string().c_str(), unsigned{ep.port()}, settings.host.c_str(),
              unsigned{settings.port}, std::string(edm::bridge::to_string(client.role())).c_str(),
              web_root.c_str());
  std::fflush(stdout);
  ioc.run();
  hub.stop();
  client.close();
  // The job is edmplc's: stopping the web server leaves it running.
  std::printf("edmhmi serve: stopped\n");
  return kExitOk;
}

}  // namespace edmhmi
