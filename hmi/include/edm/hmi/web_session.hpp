#pragma once
// One browser's WebSocket to `edmhmi serve` (docs/web.md "The WebSocket"): log-in, commands
// relayed to edmplc through the hub, and the batched frames out.
//
// - Text messages only, each decoded strictly (web_message.hpp) and handled by page_action() /
//   run_page_command() (web_command.hpp); a message that does not decode is an error reply, and
//   nothing a message does can let an exception out of the socket's handlers.
// - The first message must be {"t":"login","token":"…"} within kLoginTimeout. The token is
//   checked by a hello to edmplc (WebHub::authenticate) after the throttle of the browser's
//   address (web_login.hpp), and decides the role; a refused token closes the socket. While
//   edmplc is not there the log-in waits (the socket is told {"t":"bridge","up":false,…}).
// - A viewer's command that could act is refused here ("forbidden"), before anything is sent.
// - Messages in ≤ kMaxWebMessageBytes; at most kMaxInFlight commands in progress per browser.
// - Out: a queue bounded in bytes (web_outbox.hpp), one write in flight. A frame that does not
//   fit is dropped (counted); a browser whose frames are dropped for kStallTimeout, or whose
//   reply does not fit, is disconnected — a slow or sleeping tablet never holds the server, the
//   job or the other browsers, and a socket that asks and never reads holds ≤ kMaxQueuedBytes.
//
// Thread-safety: runs on the server's single I/O thread; send() must be called there too.

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>
#include <memory>
#include <string>

#include "edm/hmi/web_hub.hpp"
#include "edm/hmi/web_limits.hpp"

namespace edm::hmi {

inline constexpr std::size_t kMaxWebMessageBytes = kMaxWebProgramBytes + 64 * 1024;
inline constexpr int kMaxInFlight = 8;
inline constexpr auto kStallTimeout = std::chrono::seconds(5);
inline constexpr auto kLoginTimeout = std::chrono::seconds(10);

/// Who the socket is: the browser's address (the log-in throttle's key, the hello's "peer") and
/// the connection slot it holds (web_limits.hpp).
struct WebPeer {
  std::string address;
  ConnectionCounter::Slot connection, socket;
};

/// Starts a WebSocket session on an accepted upgrade request: WS over plain HTTP, WSS over HTTPS
/// (the TLS handshake already done by the HTTP session).
void start_web_socket(boost::beast::tcp_stream stream,
                      boost::beast::http::request<boost::beast::http::string_body> request,
                      WebHub& hub, WebPeer peer);
void start_web_socket(boost::beast::ssl_stream<boost::beast::tcp_stream> stream,
                      boost::beast::http::request<boost::beast::http::string_body> request,
                      WebHub& hub, WebPeer peer);

}  // namespace edm::hmi
