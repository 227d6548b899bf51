// Zero allocations on the cycle thread with the Modbus TCP I/O driver inside the composite driver:
// config/machines/drill-modbus-sim.yaml (the simulator beside a Modbus TCP remote I/O) with the
// remote I/O played by an in-process libmodbus server on a free loopback port. The driver's
// exchange thread runs for real (it connects, polls, reconnects, logs: it allocates, on its own
// thread, not counted); the cycles run on the test thread on a virtual clock, every one counted.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include "alloc/alloc_counter.hpp"
#include "alloc/drill_job.hpp"
#include "edm/blocks/register.hpp"
#include "edm/machining/motion_block.hpp"
#include "edm/modbus/driver.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/composite_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "support/files.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

// A Modbus TCP remote I/O in this process: libmodbus's server side on 127.0.0.1, a port the
// kernel picks (bound to port 0, read back: no race with other processes), one client at a time,
// served by a background thread until stop(). The tables are read and set from the test thread
// under the same mutex the server thread holds while it replies.
class LibmodbusRemoteIo {
 public:
  LibmodbusRemoteIo() {
    mapping_ = modbus_mapping_new(16, 16, 16, 16);  // coils, discrete inputs, holding, input
    ctx_ = modbus_new_tcp("127.0.0.1", 0);
    if (mapping_ == nullptr || ctx_ == nullptr) {
      return;
    }
    listen_fd_ = modbus_tcp_listen(ctx_, 1);
    if (listen_fd_ < 0) {
      return;
    }
    sockaddr_in a{};
    socklen_t len = sizeof a;
    if (::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
      return;
    }
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~LibmodbusRemoteIo() {
    stop();
    if (listen_fd_ >= 0) {
      ::close(listen_fd_);
    }
    if (ctx_ != nullptr) {
      modbus_free(ctx_);
    }
    if (mapping_ != nullptr) {
      modbus_mapping_free(mapping_);
    }
  }
  LibmodbusRemoteIo(const LibmodbusRemoteIo&) = delete;
  LibmodbusRemoteIo& operator=(const LibmodbusRemoteIo&) = delete;

  [[nodiscard]] bool ready() const { return thread_.joinable(); }
  [[nodiscard]] int port() const { return port_; }

  /// The server goes away: the connection and the listening socket are shut down (the client
  /// sees its connection end, then its reconnections refused), the thread joined.
  void stop() {
    if (!thread_.joinable()) {
      return;
    }
    {
      std::lock_guard lock(m_);
      stopping_ = true;
      if (client_fd_ >= 0) {
        ::shutdown(client_fd_, SHUT_RDWR);  // wakes modbus_receive()
      }
    }
    ::shutdown(listen_fd_, SHUT_RDWR);  // wakes accept() (EINVAL on Linux)
    thread_.join();
  }

  void set_discrete_input(int address, bool v) {
    std::lock_guard lock(m_);
    mapping_->tab_input_bits[address] = v ? 1 : 0;
  }
  void set_input_register(int address, std::uint16_t v) {
    std::lock_guard lock(m_);
    mapping_->tab_input_registers[address] = v;
  }
  bool coil(int address) {
    std::lock_guard lock(m_);
    return mapping_->tab_bits[address] != 0;
  }
  void set_coil(int address, bool v) {
    std::lock_guard lock(m_);
    mapping_->tab_bits[address] = v ? 1 : 0;
  }
  /// Requests answered so far.
  std::uint64_t served() {
    std::lock_guard lock(m_);
    return served_;
  }
  /// Blocks until more than `n` requests have been answered, or `until`; the count then.
  std::uint64_t wait_served_beyond(std::uint64_t n, std::chrono::steady_clock::time_point until) {
    std::unique_lock lock(m_);
    cv_.wait_until(lock, until, [&] { return served_ > n || stopping_; });
    return served_;
  }

 private:
  void serve() {
    for (;;) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      {
        std::lock_guard lock(m_);
        if (stopping_ || fd < 0) {
          if (fd >= 0) {
            ::close(fd);
          }
          if (stopping_) {
            return;
          }
          continue;  // EINTR, ECONNABORTED: accept again
        }
        client_fd_ = fd;
      }
      modbus_set_socket(ctx_, fd);
      std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
      for (;;) {
        const int rc = modbus_receive(ctx_, query.data());  // blocks until a request
        if (rc < 0) {
          break;  // the client left, or stop()
        }
        if (rc == 0) {
          continue;  // not for this server
        }
        std::lock_guard lock(m_);
        modbus_reply(ctx_, query.data(), rc, mapping_);
        ++served_;
        cv_.notify_all();
      }
      std::lock_guard lock(m_);
      client_fd_ = -1;
      modbus_set_socket(ctx_, -1);
      ::close(fd);
    }
  }

  modbus_t* ctx_{nullptr};
  modbus_mapping_t* mapping_{nullptr};
  int listen_fd_{-1};
  int port_{0};
  std::thread thread_;
  std::mutex m_;
  std::condition_variable cv_;
  bool stopping_{false};     // guarded by m_
  int client_fd_{-1};        // guarded by m_
  std::uint64_t served_{0};  // guarded by m_
};

// config/machines/drill-modbus-sim.yaml with the remote I/O at `port` (the modbus_server and
// bridge sections are edmplc's, not the Runtime's: left as shipped, nothing listens on them).
std::string drill_modbus_sim(int port) {
  std::string text =
      read_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-modbus-sim.yaml");
  const std::string shipped = "host: 127.0.0.1, port: 1502,";
  EXPECT_NE(text.find(shipped), std::string::npos) << "the shipped remote I/O address moved";
  return std::regex_replace(text, std::regex(shipped),
                            "host: 127.0.0.1, port: " + std::to_string(port) + ",");
}

std::unique_ptr<rt::Runtime> build_drill_modbus_sim(int port) {
  static const auto registries = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    blocks::register_builtin_blocks(r.first);
    programs::register_builtin_programs(r.first);
    sim::register_sim_driver(r.second);
    modbus::register_modbus_driver(r.second);
    return r;
  }();
  auto r = rt::Runtime::build(
      rt::parse_config_text(drill_modbus_sim(port),
                            std::string(EDM_SOURCE_DIR) + "/config/machines/drill-modbus-sim.yaml"),
      registries.first, registries.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  return r;
}

// The modbus child of the composite driver (the second of drill-modbus-sim's `drivers:`).
modbus::ModbusDriver& modbus_child(rt::Runtime& r) {
  auto& composite = dynamic_cast<rt::CompositeDriver&>(r.driver());
  return dynamic_cast<modbus::ModbusDriver&>(composite.child(1));
}

bool has_alarm(rt::Runtime& r, rt::AlarmCode code) {
  std::array<rt::ActiveAlarm, 64> a{};
  const std::size_t n = r.machine().active_alarms(a.data(), a.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (a[i].code == code) {
      return true;
    }
  }
  return false;
}

// The driver's thread started and stopped as Runtime::run does (start before the first cycle:
// its first exchange is made there; stop after the last).
struct DriverThread {
  rt::IoDriver& driver;
  explicit DriverThread(rt::IoDriver& d) : driver(d) { driver.start(); }
  ~DriverThread() { driver.stop(); }
  DriverThread(const DriverThread&) = delete;
  DriverThread& operator=(const DriverThread&) = delete;
};

// The two tasks of drill-modbus-sim on a virtual clock, motion (the I/O task) every 1 ms and
// supervisor every 10 ms, every cycle counted on this thread. The trace is drained (non-RT) now
// and then between cycles.
class Cycles {
 public:
  explicit Cycles(rt::Runtime& r) : r_(r) {}

  /// Runs `n` 1 ms steps; the allocations made inside them on this thread.
  std::size_t run(int n) {
    std::size_t total = 0;
    for (int i = 0; i < n; ++i, ++k_) {
      const rt::TimePoint release{1ms * k_};
      clock_.advance_to(release);
      total += allocations_in([&] {
        r_.tasks()[0]->run_cycle(release, clock_);
        if (k_ % 10 == 0) {
          r_.tasks()[1]->run_cycle(release, clock_);
        }
      });
      if (k_ % 500 == 499) {
        r_.trace().drain(sink_);
        sink_.str("");
      }
    }
    return total;
  }
  [[nodiscard]] std::int64_t cycles() const { return k_; }

 private:
  rt::Runtime& r_;
  rt::VirtualClock clock_;
  std::int64_t k_{0};
  std::ostringstream sink_;
};

// Waits until the driver has published an input image after the first `after` (its exchange
// counter, incremented just after the publication). It blocks on the server's answers (each one
// notifies); the wait is capped at 2 ms because the image is published just after the last
// answer of an exchange, and the next answer is a poll_interval later. False after 5 s.
bool wait_for_image(modbus::ModbusDriver& d, LibmodbusRemoteIo& io, std::uint64_t after) {
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  std::uint64_t served = io.served();
  while (d.counters().exchanges <= after) {
    if (std::chrono::steady_clock::now() >= deadline) {
      return false;
    }
    served =
        io.wait_served_beyond(served, std::min(deadline, std::chrono::steady_clock::now() + 2ms));
  }
  return true;
}

// The virtual clock is far faster than the exchange (poll_interval 10 ms of real time) and the
// image's age is counted in cycles (stale_cycles 100): `n` cycles in chunks of 20, each followed
// by a wait for one more input image, so that the image the cycles see is never older than 20
// cycles. False if an image did not come.
bool run_paced(Cycles& c, modbus::ModbusDriver& d, LibmodbusRemoteIo& io, int n,
               std::size_t& allocations) {
  constexpr int kChunk = 20;
  for (int done = 0; done < n; done += kChunk) {
    allocations += c.run(std::min(kChunk, n - done));
    if (!wait_for_image(d, io, d.counters().exchanges)) {
      return false;
    }
  }
  return true;
}

// The remote I/O of a machine ready to drill: door closed, E-stop chain closed (both normally
// closed contacts), 2.50 bar of flushing pressure, the pump's coil left on by someone.
void machine_ready(LibmodbusRemoteIo& io) {
  io.set_discrete_input(0, true);
  io.set_discrete_input(1, true);
  io.set_input_register(0, 250);
  io.set_coil(0, true);
}

// drill-modbus-sim against a remote I/O ready to drill, the driver's exchange thread running and
// the first image in: where both tests start. Members go in reverse order: the cycles, the
// exchange thread, the runtime, the remote I/O.
class AllocationsModbus : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(io.ready()) << "libmodbus server: " << modbus_strerror(errno);
    machine_ready(io);
    runtime = build_drill_modbus_sim(io.port());
    driver = &modbus_child(*runtime);
    thread.emplace(runtime->driver());
    ASSERT_TRUE(wait_for_image(*driver, io, 0)) << "the first image (start() tries it itself)";
    cycles.emplace(*runtime);
  }

  LibmodbusRemoteIo io;
  std::unique_ptr<rt::Runtime> runtime;
  modbus::ModbusDriver* driver{nullptr};
  std::optional<DriverThread> thread;
  std::optional<Cycles> cycles;
};

TEST_F(AllocationsModbus, NoneInsideCyclesWhileAJobDrillsWithTheRemoteIoExchanging) {
  auto& r = runtime;
  modbus::ModbusDriver& d = *driver;
  Cycles& c = *cycles;
  std::size_t allocations = 0;

  // Idle: the image flows both ways. edmplc turns the pump off (no job: flushing off).
  ASSERT_TRUE(run_paced(c, d, io, 200, allocations));
  EXPECT_EQ(r->variables().read("io.remote_io_ok"), 1.0) << "the input image is fresh";
  EXPECT_EQ(r->variables().read("io.door_closed"), 1.0);
  EXPECT_EQ(r->variables().read("io.estop_ok"), 1.0);
  EXPECT_DOUBLE_EQ(r->variables().read("io.flush_pressure_bar").value(), 2.5);
  EXPECT_FALSE(io.coil(0)) << "the driver wrote the pump's coil off";
  ASSERT_EQ(r->machine().state(), rt::MachineState::kReady);

  // A job from the JobStore (non-RT, between cycles), drilled for 3 s with the exchange running.
  // With M08: the job switches the flushing pump, a coil of the remote I/O (io.flush_pump), on.
  ASSERT_EQ(r->job().load(drill_job(/*flushing=*/true)), rt::LoadResult::kOk);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  ASSERT_TRUE(run_paced(c, d, io, 1500, allocations));
  io.set_input_register(0, 310);  // the pressure rises on the remote side
  ASSERT_TRUE(run_paced(c, d, io, 1500, allocations));

  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(c.cycles(), 3200);
  EXPECT_GT(d.counters().exchanges, 3200u / 20u) << "an image per chunk of cycles";
  EXPECT_EQ(r->variables().read("io.remote_io_ok"), 1.0) << "still fresh";
  EXPECT_FALSE(has_alarm(*r, rt::AlarmCode::kIoStale));
  EXPECT_DOUBLE_EQ(r->variables().read("io.flush_pressure_bar").value(), 3.1)
      << "a change on the server reached the machine";
  EXPECT_GT(r->variables().read("io.depth_mm").value(), 0.1) << "it really drilled";
  EXPECT_EQ(r->variables().read("cnc.job.drill.state"), 2.0)
      << "drilling from the job; machine " << rt::to_string(r->machine().state()) << ", cause "
      << static_cast<int>(r->machine().last_cause());
  EXPECT_EQ(r->variables().read("cnc.job.flushing_on"), 1.0);
  // The pump's coil follows the job's flushing, through the output image, within an exchange.
  ASSERT_TRUE(run_paced(c, d, io, 20, allocations));
  EXPECT_TRUE(io.coil(0)) << "the flushing pump is on on the remote I/O";
  EXPECT_EQ(allocations, 0u);
}

TEST_F(AllocationsModbus, NoneInsideCyclesWhenTheRemoteIoGoesAwayMidJob) {
  auto& r = runtime;
  modbus::ModbusDriver& d = *driver;
  Cycles& c = *cycles;
  std::size_t allocations = 0;
  // With M08: the job switches the flushing pump, a coil of the remote I/O (io.flush_pump), on.
  ASSERT_EQ(r->job().load(drill_job(/*flushing=*/true)), rt::LoadResult::kOk);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  ASSERT_TRUE(run_paced(c, d, io, 1500, allocations));
  ASSERT_EQ(r->variables().read("io.remote_io_ok"), 1.0);
  ASSERT_EQ(r->machine().state(), rt::MachineState::kRunning)
      << rt::to_string(r->machine().state());
  ASSERT_EQ(r->variables().read("io.gen_on"), 1.0) << "sparking when the remote I/O goes";

  // The coupler goes away: the driver's thread sees its connection end and then refused
  // connections (it logs, backs off, retries: all on its own thread). No image comes any more:
  // 100 cycles on, alarm 121 and the safe state. Every one of these cycles is counted.
  const std::uint64_t errors_before = d.counters().errors;
  io.stop();
  const std::size_t after_stop = c.run(1000);
  EXPECT_EQ(after_stop, 0u);
  allocations += after_stop;
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(r->machine().last_cause(), rt::AlarmCode::kIoStale);
  EXPECT_TRUE(has_alarm(*r, rt::AlarmCode::kIoStale));
  EXPECT_EQ(r->variables().read("io.remote_io_ok"), 0.0);
  EXPECT_EQ(r->variables().read("io.gen_on"), 0.0) << "generator off in the safe state";

  // The exchange thread really failed (and logged) while the cycles ran on: its error count,
  // waited for with a deadline by running more counted cycles of the safe state.
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (d.counters().errors == errors_before && std::chrono::steady_clock::now() < deadline) {
    allocations += c.run(10);
  }
  EXPECT_GT(d.counters().errors, errors_before);
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
}

}  // namespace
}  // namespace edm::test
