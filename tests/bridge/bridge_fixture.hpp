#pragma once
// An in-process runtime (loopback driver, real clock, 1 kHz task) with a bridge server on an
// ephemeral loopback port, and helpers to wait for events without sleeping.

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <fstream>
#include <memory>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/bridge/server.hpp"
#include "edm/machining/motion_block.hpp"
#include "support/bridge_test_config.hpp"
#include "support/runtime_fixture.hpp"
#include "support/runtime_thread.hpp"
#include "support/temp_dir.hpp"

namespace edm::bridge::test {

using edm::test::kBridgeTestConfig;

/// A raw TCP client: a socket that connects and then does only what the test says (never reads
/// unless asked), for clients that misbehave on purpose.
class RawSocket {
 public:
  explicit RawSocket(std::uint16_t port, int rcvbuf = 0) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (rcvbuf > 0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    }
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ok_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~RawSocket() { ::close(fd_); }
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;
  [[nodiscard]] bool ok() const { return ok_; }
  /// Writes what the socket takes without blocking; returns the bytes written.
  std::size_t send_some(std::string_view s) {
    const ssize_t n = ::send(fd_, s.data(), s.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    return n > 0 ? static_cast<std::size_t>(n) : 0;
  }
  void send(std::string_view s) {
    std::size_t done = 0;
    while (done < s.size()) {
      const ssize_t n = ::send(fd_, s.data() + done, s.size() - done, MSG_NOSIGNAL);
      if (n <= 0) {
        return;
      }
      done += static_cast<std::size_t>(n);
    }
  }
  /// Reads until `pred(all read so far)` or close/timeout; returns what was read.
  template <class Pred>
  std::string read_until(Pred pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!pred(buf_) && std::chrono::steady_clock::now() < end) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) > 0) {
        char b[65536];
        const ssize_t n = ::read(fd_, b, sizeof b);
        if (n <= 0) {
          closed_ = true;
          break;
        }
        buf_.append(b, static_cast<std::size_t>(n));
      }
    }
    return buf_;
  }
  std::string read_line(std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
    read_until([](const std::string& b) { return b.find('\n') != std::string::npos; }, timeout);
    const auto nl = buf_.find('\n');
    if (nl == std::string::npos) {
      return "";
    }
    std::string line = buf_.substr(0, nl);
    buf_.erase(0, nl + 1);
    return line;
  }
  bool closed_within(std::chrono::milliseconds timeout) {
    read_until([this](const std::string&) { return closed_; }, timeout);
    return closed_;
  }

 private:
  int fd_{-1};
  bool ok_{false};
  bool closed_{false};
  std::string buf_;
};

/// Collects events from a Client's handler; waits with a deadline on a condition variable.
class EventSink {
 public:
  void operator()(const Json& ev) {
    {
      std::lock_guard lock(mu_);
      events_.push_back(ev);
    }
    cv_.notify_all();
  }
  Client::EventHandler handler() {
    return [this](const Json& ev) { (*this)(ev); };
  }
  /// Waits until `n` events named `name` arrived; returns them (fewer on timeout).
  std::vector<Json> wait_for(const std::string& name, std::size_t n,
                             std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mu_);
    std::vector<Json> out;
    cv_.wait_for(lock, timeout, [&] {
      out.clear();
      for (const auto& e : events_) {
        if (e.value("event", "") == name) {
          out.push_back(e);
        }
      }
      return out.size() >= n;
    });
    return out;
  }
  /// Waits until pred(all events) holds; false on timeout.
  template <class Pred>
  bool wait_until(Pred pred, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return pred(events_); });
  }
  std::vector<Json> all() {
    std::lock_guard lock(mu_);
    return events_;
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Json> events_;
};

inline void write_token(const std::string& path, const std::string& token, mode_t mode) {
  std::ofstream(path) << token << "\n";
  ::chmod(path.c_str(), mode);
}

/// A bridge server for `rt` on an ephemeral loopback port (whatever opt.port says), started.
inline std::unique_ptr<Server> start_server(rt::Runtime& rt, ServerOptions opt = {}) {
  opt.port = 0;
  auto server = std::make_unique<Server>(rt, opt);
  server->start();
  return server;
}

/// How a test client reaches `server`: its port, `token`, 10 s timeouts.
inline ClientOptions client_options(const Server& server, const std::string& token = "") {
  ClientOptions o;
  o.port = server.port();
  o.token = token;
  o.timeout = std::chrono::seconds(10);
  return o;
}

class BridgeFixture : public ::testing::Test {
 protected:
  /// Builds the runtime and starts the server with `opt` (port 0), then runs the tasks.
  void start(ServerOptions opt = {}) {
    rt_ = edm::test::build_from_text(kBridgeTestConfig, "bridge-test.yaml");
    server_ = start_server(*rt_, opt);
    runner_.start(*rt_);  // the real clock
    ASSERT_TRUE(runner_.wait_until_powered_on()) << "the runtime did not start";
  }
  void TearDown() override {
    runner_.stop();
    if (server_) {
      server_->stop();
    }
  }
  /// Routes `c`'s events to `sink`, then connects. Declare the sink before the client: it must
  /// outlive the client's I/O thread.
  Role connect_with_events(Client& c, EventSink& sink) {
    c.set_event_handler(sink.handler());
    return c.connect(client_opts());
  }
  ClientOptions client_opts(const std::string& token = "") const {
    return client_options(*server_, token);
  }

  edm::test::TempDir dir_{"edm-bridge"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  edm::test::RuntimeThread runner_;
};

/// A watchdog warning from `source` (static strings, as the RT side raises alarms).
inline rt::Alarm warning_alarm(const char* source, const char* text) {
  rt::Alarm a;
  a.code = rt::AlarmCode::kWatchdogWarning;
  a.severity = rt::AlarmSeverity::kWarning;
  a.source = source;
  a.text = text;
  return a;
}

inline void expect_error(const Reply& r, ErrorCode code) {
  EXPECT_FALSE(r.ok) << r.body;
  ASSERT_TRUE(r.code.has_value()) << "transport error: " << r.message;
  EXPECT_EQ(to_string(*r.code), to_string(code)) << r.message;
}

/// Every event's seq follows the previous one by exactly 1.
inline void expect_no_gaps(const std::vector<Json>& events) {
  for (std::size_t i = 1; i < events.size(); ++i) {
    ASSERT_EQ(events[i]["seq"].get<std::uint64_t>(), events[i - 1]["seq"].get<std::uint64_t>() + 1)
        << "at event " << i;
  }
}

/// A program's blocks for tests that only need a job to run: a dwell, the end.
inline machining::MotionBlock dwell_block(double seconds, std::int32_t line) {
  machining::MotionBlock b;
  b.kind = machining::MotionKind::kDwell;
  b.dwell_s = seconds;
  b.line = line;
  return b;
}
inline machining::MotionBlock end_block(std::int32_t line) {
  machining::MotionBlock b;
  b.kind = machining::MotionKind::kEnd;
  b.line = line;
  return b;
}

}  // namespace edm::bridge::test
