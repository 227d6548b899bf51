#pragma once
// The Modbus TCP server of edmplc (`modbus_server:`, docs/modbus.md): configured variables as
// coils, discrete inputs, input registers and holding registers, for an HMI panel or a SCADA
// system. It runs on a thread of its own, never an RT one, and reaches the tasks only through
// the variable registry (server_registers.hpp): lock-free pin loads, parameter shadow copies,
// and writes queued to the owning task's bounded queue.
//
// The protocol (server_pdu.hpp): functions 1-6, 15, 16; exception 01 for every other function
// code, with the function byte | 0x80. Framing is this server's own: MBAP checked (protocol 0,
// length 2..254, at most 260 bytes); a frame that is not Modbus TCP closes its connection; any
// unit identifier is answered and echoed. Nothing waits on a client: sockets are non-blocking;
// a frame begun must be complete within `frame_timeout`, a reply must be taken by the client
// within it, a connection without a request for `idle_timeout` is closed, and who keeps a slot
// when a new connection comes is server_slots.hpp's rule (`max_clients`, and at most
// `max_clients_per_address` per peer address). The log names peers by address, every line
// about one address rate-limited (`log_burst`, `log_per_s`; all addresses together ten times
// that, as any local process can take any 127.x.y.z); names that reach it are escaped.
// Memory: fixed per connection (a 260-byte frame and a 260-byte reply).
//
// Thread-safety: start()/stop() from one controlling thread; counters() from any thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "edm/modbus/server_config.hpp"
#include "edm/modbus/server_registers.hpp"
#include "edm/runtime/log_limiter.hpp"
#include "edm/runtime/variables.hpp"

namespace edm::modbus {

class Server {
 public:
  Server(rt::VariableRegistry& vars, ServerConfig config);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds and starts the thread. Throws std::runtime_error when it cannot bind.
  void start();
  void stop() noexcept;
  /// The bound port (after start(); useful with port 0).
  [[nodiscard]] int port() const noexcept { return bound_port_; }

  struct Counters {
    std::uint64_t requests{0};         // complete frames served
    std::uint64_t exceptions{0};       // of them answered with an exception
    std::uint64_t writes{0};           // values written to parameters
    std::uint64_t accepted{0};         // connections accepted (admitted or not)
    std::uint64_t refused_clients{0};  // closed at once: every slot serving a client
    std::uint64_t evicted{0};          // closed to make room for a newer connection
    std::uint64_t bad_frames{0};       // closed: not a Modbus TCP frame
    std::uint64_t frame_timeouts{0};   // closed: a frame unfinished after frame_timeout
    std::uint64_t stalled{0};          // closed: a reply not taken within frame_timeout
    std::uint64_t idle_timeouts{0};    // closed: no request for idle_timeout
    std::uint64_t open{0};             // connections now
    std::uint64_t log_suppressed{0};   // log lines dropped by the per-address rate limit
  };
  [[nodiscard]] Counters counters() const noexcept;

 private:
  struct Client;
  enum class Close : std::uint8_t;
  using Clock = std::chrono::steady_clock;

  void run() noexcept;
  void accept_one(std::vector<std::unique_ptr<Client>>& clients, Clock::time_point now);
  /// Reads, serves and writes what poll() reported, then checks the deadlines; a reason to
  /// close, or kKeep.
  Close service(Client& c, short revents, Clock::time_point now);
  Close receive(Client& c, Clock::time_point now);
  Close serve_buffered(Client& c, Clock::time_point now);
  void serve_frame(Client& c, std::size_t total, Clock::time_point now);
  [[nodiscard]] bool flush(Client& c) noexcept;
  Close check_deadlines(const Client& c, Clock::time_point now) const noexcept;
  [[nodiscard]] Clock::time_point deadline(const Client& c) const noexcept;
  void close_client(std::vector<std::unique_ptr<Client>>& clients, std::size_t i, Close why,
                    Clock::time_point now);
  /// A line about `address`, through the per-address rate limit.
  void log_about(int level, const std::string& address, const std::string& line);

  rt::VariableRegistry& vars_;
  ServerConfig config_;
  MapRegisters regs_;               // over config_.map
  rt::LogRateLimiter limiter_;      // per peer address: log_burst, log_per_s
  rt::LogRateLimiter all_limiter_;  // every address together: ten times that
  int listen_fd_{-1};
  int bound_port_{0};
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  // Accepting paused after EMFILE & co. (10 ms doubling to 1 s), so a full descriptor table
  // does not spin the thread; one warning per episode.
  Clock::time_point accept_resume_{};
  std::chrono::milliseconds accept_backoff_{0};
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<std::uint64_t> exceptions_{0};
  std::atomic<std::uint64_t> writes_{0};
  std::atomic<std::uint64_t> accepted_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> evicted_{0};
  std::atomic<std::uint64_t> bad_frames_{0};
  std::atomic<std::uint64_t> frame_timeouts_{0};
  std::atomic<std::uint64_t> stalled_{0};
  std::atomic<std::uint64_t> idle_timeouts_{0};
  std::atomic<std::uint64_t> open_{0};
};

}  // namespace edm::modbus
