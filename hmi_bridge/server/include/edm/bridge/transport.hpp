#pragma once
// The byte stream under a bridge session: plain TCP, TLS over TCP, or an in-memory stream for
// tests and fuzzing. The session speaks JSON Lines over it and never knows which it has.
//
// Thread-safety: none; every call and every handler runs on the bridge server's single io
// thread (the io_context the transport was made with). Not RT-safe (allocates).

#include <boost/asio/buffer.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/system/error_code.hpp>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace boost::asio::ssl {
class context;
}

namespace edm::bridge {

class Transport {
 public:
  using Handler = std::function<void(boost::system::error_code)>;
  using IoHandler = std::function<void(boost::system::error_code, std::size_t)>;

  virtual ~Transport() = default;

  /// TLS: the server side of the handshake. Plain: completes at once.
  virtual void async_handshake(Handler h) = 0;
  virtual void async_read_some(boost::asio::mutable_buffer buf, IoHandler h) = 0;
  /// Writes all of `buf` (one write in flight at a time).
  virtual void async_write(boost::asio::const_buffer buf, IoHandler h) = 0;
  /// Graceful end after the last reply: plain sends FIN and reads (and drops) what the peer
  /// still sends until it closes; TLS exchanges close_notify. Completes when the peer closed
  /// or on error. No read may be in flight when it starts.
  virtual void async_shutdown(Handler h) = 0;
  /// Cancels what is in flight (handlers complete with operation_aborted).
  virtual void cancel() = 0;
  virtual void close() = 0;

  /// The peer's IP address ("" when unknown), and "address:port" for logs.
  [[nodiscard]] virtual std::string peer_address() const = 0;
  [[nodiscard]] virtual std::string peer() const = 0;
  [[nodiscard]] virtual bool encrypted() const = 0;
};

/// Plain TCP over a connected socket.
std::unique_ptr<Transport> make_tcp_transport(boost::asio::ip::tcp::socket socket);
/// TLS over a connected socket, with the server's context (certificate and key loaded). A peer
/// that speaks plain JSON instead of TLS gets one plaintext `unauthorized` error line ("this
/// port speaks TLS"), then the connection closes.
std::unique_ptr<Transport> make_tls_transport(boost::asio::ip::tcp::socket socket,
                                              boost::asio::ssl::context& ctx);

/// The bridge's TLS server context from PEM files (TLS 1.2 or later). Throws BridgeError naming
/// the file that could not be used.
std::shared_ptr<boost::asio::ssl::context> make_tls_server_context(const std::string& cert_file,
                                                                   const std::string& key_file);

}  // namespace edm::bridge
