// Plain TCP transport of a bridge session.
#include <array>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include "edm/bridge/transport.hpp"

namespace edm::bridge {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {

class TcpTransport final : public Transport {
 public:
  explicit TcpTransport(tcp::socket s) : socket_(std::move(s)) {
    boost::system::error_code ec;
    const auto ep = socket_.remote_endpoint(ec);
    if (!ec) {
      address_ = ep.address().to_string();
      peer_ = address_ + ":" + std::to_string(ep.port());
    }
    socket_.set_option(tcp::no_delay(true), ec);
  }

  void async_handshake(Handler h) override {
    asio::post(socket_.get_executor(), [h = std::move(h)] { h({}); });
  }
  void async_read_some(asio::mutable_buffer buf, IoHandler h) override {
    socket_.async_read_some(buf, std::move(h));
  }
  void async_write(asio::const_buffer buf, IoHandler h) override {
    asio::async_write(socket_, buf, std::move(h));
  }
  void async_shutdown(Handler h) override {
    boost::system::error_code ec;
    socket_.shutdown(tcp::socket::shutdown_send, ec);
    if (ec) {
      asio::post(socket_.get_executor(), [h = std::move(h), ec] { h(ec); });
      return;
    }
    drain(std::make_shared<Handler>(std::move(h)));
  }
  void cancel() override {
    boost::system::error_code ec;
    socket_.cancel(ec);
  }
  void close() override {
    boost::system::error_code ec;
    socket_.shutdown(tcp::socket::shutdown_both, ec);
    socket_.close(ec);
  }
  [[nodiscard]] std::string peer_address() const override { return address_; }
  [[nodiscard]] std::string peer() const override { return peer_; }
  [[nodiscard]] bool encrypted() const override { return false; }

 private:
  // Reads and drops until the peer closes: closing with unread input would send an RST, and the
  // peer's stack may then drop the reply it has not read yet.
  void drain(std::shared_ptr<Handler> h) {
    socket_.async_read_some(asio::buffer(scratch_),
                            [this, h](boost::system::error_code ec, std::size_t) {
                              if (ec) {
                                (*h)(ec == asio::error::eof ? boost::system::error_code{} : ec);
                                return;
                              }
                              drain(h);
                            });
  }

  tcp::socket socket_;
  std::string address_;
  std::string peer_;
  std::array<char, 4096> scratch_{};
};

}  // namespace

std::unique_ptr<Transport> make_tcp_transport(tcp::socket socket) {
  return std::make_unique<TcpTransport>(std::move(socket));
}

}  // namespace edm::bridge
