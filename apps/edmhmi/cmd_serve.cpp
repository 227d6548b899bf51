// edmhmi serve [--listen HOST:PORT] [--web-root DIR] [--tls-cert F --tls-key F] [--allow-host N]…
// — the operator's screen in a browser (docs/web.md): serves the built page and a WebSocket
// (HTTPS/WSS with a certificate), owns one bridge session to edmplc and the job, relays commands
// for logged-in browsers. It serves the page before edmplc is there and waits for it (and again
// after edmplc restarts), saying so on the page.
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/signal_set.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "cli.hpp"
#include "edm/hmi/web_http.hpp"
#include "edm/hmi/web_hub.hpp"
#include "edm/hmi/web_tls.hpp"

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

/// The page's transport against the bridge's (docs/security.md "The browser HMI"): plain HTTP
/// when the bridge is TLS would put the operator's token in clear on the one hop left unprotected.
/// On loopback it stays allowed with a warning (nothing leaves the host); elsewhere it needs
/// --insecure-http. Plain HTTP off loopback needs --insecure-listen or --insecure-http anyway.
/// Returns false after printing the one-line refusal.
bool plain_http_allowed(const ServeArgs& args, const edm::hmi::ConnectionSettings& settings,
                        const boost::asio::ip::tcp::endpoint& endpoint) {
  const bool bridge_tls = !settings.tls_ca_file.empty() || !settings.tls_fingerprint.empty();
  const bool loopback = endpoint.address().is_loopback();
  if (args.insecure_http) return true;
  if (bridge_tls && !loopback) {
    std::fprintf(stderr,
                 "edmhmi serve: the bridge uses TLS but the page on %s would be plain HTTP: give "
                 "--tls-cert and --tls-key (or --insecure-http to accept tokens in clear)\n",
                 args.listen.c_str());
    return false;
  }
  if (bridge_tls) {
    std::fprintf(stderr,
                 "edmhmi serve: warning: the bridge uses TLS but the page is plain HTTP on "
                 "loopback %s (--tls-cert and --tls-key for HTTPS)\n",
                 args.listen.c_str());
    return true;
  }
  if (!loopback && !args.insecure) {
    std::fprintf(stderr,
                 "edmhmi serve: %s is not a loopback address: the page speaks plain HTTP and "
                 "tokens would cross the network in clear. Give --tls-cert and --tls-key, use an "
                 "SSH tunnel, or --insecure-listen on a network you trust (docs/web.md).\n",
                 args.listen.c_str());
    return false;
  }
  return true;
}

/// --allow-host's names, then $EDM_WEB_ALLOW_HOSTS's (separated by commas or white space).
std::vector<std::string> allowed_names(const ServeArgs& args) {
  std::vector<std::string> names = args.allow_hosts;
  if (const char* env = std::getenv("EDM_WEB_ALLOW_HOSTS")) {
    std::string word;
    for (const char* p = env;; ++p) {
      if (*p == '\0' || *p == ',' || *p == ' ' || *p == '\t') {
        if (!word.empty()) names.push_back(word);
        word.clear();
        if (*p == '\0') break;
      } else {
        word.push_back(*p);
      }
    }
  }
  return names;
}

}  // namespace

int cmd_serve(const ServeArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const std::string& listen = args.listen;
  const std::string& web_root = args.web_root;
  boost::asio::ip::tcp::endpoint endpoint;
  std::string why;
  if (!parse_listen(listen, endpoint, why)) return usage(why);
  if (args.tls_cert.empty() != args.tls_key.empty()) {
    return usage(args.tls_cert.empty() ? "--tls-key needs --tls-cert (or $EDM_WEB_TLS_CERT)"
                                       : "--tls-cert needs --tls-key (or $EDM_WEB_TLS_KEY)");
  }
  // Every refusal comes before edmplc is contacted: a bad start-up never touches the machine.
  std::shared_ptr<boost::asio::ssl::context> tls;
  if (!args.tls_cert.empty()) {
    try {
      tls = edm::hmi::load_web_tls(args.tls_cert, args.tls_key);
    } catch (const edm::hmi::WebTlsError& e) {
      std::fprintf(stderr, "edmhmi serve: %s\n", e.what());
      return kExitBadInput;
    }
  } else if (!plain_http_allowed(args, settings, endpoint)) {
    return kExitBadInput;
  }
  std::optional<edm::hmi::HostAllowList> hosts;
  try {
    hosts.emplace(endpoint.address(), allowed_names(args), tls != nullptr);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  if (!std::filesystem::is_regular_file(std::filesystem::path(web_root) / "index.html")) {
    std::fprintf(stderr,
                 "edmhmi serve: %s/index.html missing: build the page (./edm build, or "
                 "cmake --build build --target edm_web)\n",
                 web_root.c_str());
    return kExitBadInput;
  }

  edm::bridge::Client client;
  boost::asio::io_context ioc;
  edm::hmi::WebHub hub(ioc, client, settings);
  std::shared_ptr<edm::hmi::WebListener> listener;
  try {
    listener = std::make_shared<edm::hmi::WebListener>(ioc, endpoint, web_root, hub,
                                                       std::move(*hosts), tls);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edmhmi serve: cannot listen on %s: %s\n", listen.c_str(), e.what());
    return kExitFailure;
  }
  listener->run();
  hub.start();  // connects to edmplc in the background, for as long as it takes
  boost::asio::signal_set signals(ioc, SIGINT, SIGTERM);
  signals.async_wait([&ioc](boost::system::error_code, int) { ioc.stop(); });
  const auto ep = listener->local_endpoint();
  std::printf("edmhmi serve: listening on %s://%s:%u/ (edmplc at %s:%u, page %s)\n",
              tls ? "https" : "http", ep.address().to_string().c_str(), unsigned{ep.port()},
              settings.host.c_str(), unsigned{settings.port}, web_root.c_str());
  std::fflush(stdout);
  for (;;) {  // a handler that throws ends its own connection, never the server
    try {
      ioc.run();
      break;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "edmhmi serve: a handler failed: %s\n", e.what());
    }
  }
  hub.stop();
  client.close();
  // The job is edmplc's: stopping the web server leaves it running.
  std::printf("edmhmi serve: stopped\n");
  return kExitOk;
}

}  // namespace edmhmi
