#pragma once
// An in-process runtime (loopback driver, real clock, 1 kHz task) with a bridge server on an
// ephemeral loopback port, and helpers to wait for events without sleeping.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/bridge/server.hpp"
#include "support/runtime_fixture.hpp"
#include "support/temp_dir.hpp"

namespace edm::bridge::test {

inline const char* kBridgeTestConfig = R"(version: 1
machine:
  name: bridge-test
  io: {driver: loopback, task: fast, params: {channels: 2}}
  axes:
    - {name: X, min_mm: -100, max_mm: 100}
    - {name: Y, min_mm: -100, max_mm: 100}
    - {name: Z, min_mm: -60, max_mm: 20}
conditions:
  - {E: 1, name: rough}
tasks:
  - name: fast
    interval: 1ms
    priority: 0
    programs: [chain]
programs:
  - name: chain
    blocks:
      - {name: g, type: Gain, params: {k: 1.0, offset: 0.0}}
    wires:
      g.in: io.ai0
      io.ao0: g.out
)";

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

class BridgeFixture : public ::testing::Test {
 protected:
  /// Builds the runtime and starts the server with `opt` (port 0), then runs the tasks.
  void start(ServerOptions opt = {}) {
    rt_ = edm::test::build_from_text(kBridgeTestConfig, "bridge-test.yaml");
    opt.port = 0;
    server_ = std::make_unique<Server>(*rt_, opt);
    server_->start();
    runner_ = std::thread([this] {
      rt::RunOptions ro;
      ro.clock = rt::ClockKind::kReal;
      ro.stop = &stop_;
      rt_->run(ro);
    });
    // run() powers the machine on (OFF → READY) on its thread: wait for that, not for a time.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (rt_->machine().state() == rt::MachineState::kOff &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::yield();
    }
    ASSERT_NE(rt_->machine().state(), rt::MachineState::kOff) << "the runtime did not start";
  }
  void TearDown() override {
    stop_ = true;
    if (runner_.joinable()) {
      runner_.join();
    }
    if (server_) {
      server_->stop();
    }
  }
  ClientOptions client_opts(const std::string& token = "") const {
    ClientOptions o;
    o.port = server_->port();
    o.token = token;
    o.timeout = std::chrono::seconds(10);
    return o;
  }

  edm::test::TempDir dir_{"edm-bridge"};
  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  std::atomic<bool> stop_{false};
  std::thread runner_;
};

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

}  // namespace edm::bridge::test
