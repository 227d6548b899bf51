#pragma once
// One browser's WebSocket to `edmhmi serve` (docs/web.md "The WebSocket"): log-in, commands
// relayed to edmplc through the hub, and the batched frames out.
//
// - The first message must be {"t":"login","token":"…"} within 10 s; the token is checked by a
//   hello to edmplc (WebHub::authenticate) and decides the role; a refused token closes the socket.
// - A viewer's command that could act is refused here ("forbidden"), before anything is sent.
// - Messages in ≤ kMaxWebMessageBytes; at most kMaxInFlight commands in progress per browser.
// - Out: a queue of kMaxQueued messages, one write in flight. A full queue drops (counted); a
//   browser that stays full for kStallTimeout is disconnected — a slow or sleeping tablet never
//   holds the server, the job or the other browsers.
//
// Thread-safety: runs on the server's single I/O thread; send() must be called there too.

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>
#include <memory>

#include "edm/hmi/web_hub.hpp"

namespace edm::hmi {

inline constexpr std::size_t kMaxWebMessageBytes = kMaxWebProgramBytes + 64 * 1024;
inline constexpr std::size_t kMaxQueued = 64;
inline constexpr int kMaxInFlight = 8;
inline constexpr auto kStallTimeout = std::chrono::seconds(5);
inline constexpr auto kLoginTimeout = std::chrono::seconds(10);

/// Starts a WebSocket session on an accepted upgrade request: WS over plain HTTP, WSS over HTTPS
/// (the TLS handshake already done by the HTTP session).
void start_web_socket(boost::beast::tcp_stream stream,
                      boost::beast::http::request<boost::beast::http::string_body> request,
                      WebHub& hub);
void start_web_socket(boost::beast::ssl_stream<boost::beast::tcp_stream> stream,
                      boost::beast::http::request<boost::beast::http::string_body> request,
                      WebHub& hub);

}  // namespace edm::hmi
