#pragma once
// An in-memory bridge transport: a session over it runs the real line framing, limits and
// dispatcher with no socket (tests and the protocol fuzzer). The test side talks to it through
// a MemoryPeer: send() bytes in, wait_for() text out, close() the input.
//
// Thread-safety: MemoryPeer's members may be called from any thread; the transport itself runs
// on the server's io thread (everything it touches there is posted to it).

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "edm/bridge/transport.hpp"

namespace edm::test {

namespace asio = boost::asio;

/// State shared by the transport (io thread) and the peer (test thread).
struct MemoryPipe {
  explicit MemoryPipe(asio::io_context& io) : ioc(io) {}
  asio::io_context& ioc;
  // io thread only:
  std::string inbox;
  bool input_closed{false};
  bool transport_closed{false};
  asio::mutable_buffer read_buf{};
  bridge::Transport::IoHandler read_handler;
  // guarded by mu:
  std::mutex mu;
  std::condition_variable cv;
  std::string outbox;
  bool closed{false};

  /// Completes a waiting read if there is something to give it (io thread).
  void deliver() {
    if (!read_handler) {
      return;
    }
    auto h = std::move(read_handler);
    read_handler = nullptr;
    if (transport_closed) {
      h(asio::error::operation_aborted, 0);
    } else if (!inbox.empty()) {
      const std::size_t n = std::min(inbox.size(), read_buf.size());
      std::memcpy(read_buf.data(), inbox.data(), n);
      inbox.erase(0, n);
      h({}, n);
    } else if (input_closed) {
      h(asio::error::eof, 0);
    } else {
      read_handler = std::move(h);
    }
  }
};

class MemoryTransport final : public bridge::Transport {
 public:
  MemoryTransport(std::shared_ptr<MemoryPipe> pipe, std::string address)
      : pipe_(std::move(pipe)), address_(std::move(address)) {}

  void async_handshake(Handler h) override {
    asio::post(pipe_->ioc, [h = std::move(h)] { h({}); });
  }
  void async_read_some(asio::mutable_buffer buf, IoHandler h) override {
    pipe_->read_buf = buf;
    pipe_->read_handler = std::move(h);
    asio::post(pipe_->ioc, [p = pipe_] { p->deliver(); });
  }
  void async_write(asio::const_buffer buf, IoHandler h) override {
    {
      std::lock_guard lock(pipe_->mu);
      pipe_->outbox.append(static_cast<const char*>(buf.data()), buf.size());
    }
    pipe_->cv.notify_all();
    asio::post(pipe_->ioc, [h = std::move(h), n = buf.size()] { h({}, n); });
  }
  void async_shutdown(Handler h) override {
    asio::post(pipe_->ioc, [h = std::move(h)] { h({}); });
  }
  void cancel() override {
    if (pipe_->read_handler) {
      auto h = std::move(pipe_->read_handler);
      pipe_->read_handler = nullptr;
      asio::post(pipe_->ioc, [h = std::move(h)] { h(asio::error::operation_aborted, 0); });
    }
  }
  void close() override {
    pipe_->transport_closed = true;
    cancel();
    {
      std::lock_guard lock(pipe_->mu);
      pipe_->closed = true;
    }
    pipe_->cv.notify_all();
  }
  [[nodiscard]] std::string peer_address() const override { return address_; }
  [[nodiscard]] std::string peer() const override { return address_ + ":0"; }
  [[nodiscard]] bool encrypted() const override { return false; }

 private:
  std::shared_ptr<MemoryPipe> pipe_;
  std::string address_;
};

/// The client's end of a MemoryTransport.
class MemoryPeer {
 public:
  /// A transport for Server::adopt(), and this peer on its other end.
  explicit MemoryPeer(asio::io_context& ioc) : pipe_(std::make_shared<MemoryPipe>(ioc)) {}
  std::unique_ptr<bridge::Transport> transport(std::string address = "127.0.0.1") {
    return std::make_unique<MemoryTransport>(pipe_, std::move(address));
  }

  void send(std::string bytes) {
    asio::post(pipe_->ioc, [p = pipe_, b = std::move(bytes)] {
      p->inbox += b;
      p->deliver();
    });
  }
  /// End of the client's input (EOF on the server's side).
  void close_input() {
    asio::post(pipe_->ioc, [p = pipe_] {
      p->input_closed = true;
      p->deliver();
    });
  }
  /// Waits until the server's output contains `text` (true) or the session closed or the
  /// timeout passed (false).
  bool wait_for(const std::string& text,
                std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(pipe_->mu);
    pipe_->cv.wait_for(lock, timeout, [&] {
      return pipe_->outbox.find(text) != std::string::npos || pipe_->closed;
    });
    return pipe_->outbox.find(text) != std::string::npos;
  }
  bool wait_closed(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(pipe_->mu);
    return pipe_->cv.wait_for(lock, timeout, [&] { return pipe_->closed; });
  }
  std::string output() {
    std::lock_guard lock(pipe_->mu);
    return pipe_->outbox;
  }

 private:
  std::shared_ptr<MemoryPipe> pipe_;
};

}  // namespace edm::test
