#pragma once
// The bridge server inside edmplc (DESIGN §9, docs/protocol.md): JSON Lines over TCP on its own
// non-RT thread running a Boost.Asio io_context. Listener / session / shared state as in the
// Beast examples: one strand per session, one write in flight with a bounded queue, a timeout on
// every read, a 1 MiB line limit.
//
// What it touches in the runtime, and how (the RT tasks never wait for the bridge):
//  - status: a StatusBoard (seqlock) the I/O task publishes at the end of each cycle;
//  - alarms: an alarm listener on the runtime's controlling thread, posted to the io thread;
//  - trace: one TraceTap per task (its own SPSC ring, independent of --trace-out);
//  - commands: Machine::command() (lock-free), VariableRegistry (non-RT API), JobStore::load().
//
// Lifecycle: construct → start() (before Runtime::run(): it attaches observers and the alarm
// listener) → Runtime::run() → stop() → destroy, then destroy the Runtime.
// Thread-safety: start(), stop() and the destructor from the controlling thread; port() and
// stats() from any thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "edm/bridge/auth.hpp"
#include "edm/bridge/transport.hpp"
#include "edm/runtime/config.hpp"

namespace edm::rt {
class Runtime;
}

namespace edm::bridge {

struct ServerOptions {
  std::string bind{"127.0.0.1"};
  std::uint16_t port{kDefaultPort};  // 0: an ephemeral port (tests); see port()
  std::string token_file;            // operator role
  std::string viewer_token_file;     // viewer role
  int max_sessions{8};
  std::size_t max_line_bytes{kMaxLineBytes};
  std::chrono::milliseconds read_timeout{60'000};  // no complete line for this long: close
  std::size_t queue_limit{256};                    // queued messages per session before dropping
  std::chrono::milliseconds stall_timeout{5'000};  // dropping events this long: disconnect
  std::size_t queue_bytes{std::size_t{4} << 20};   // queued bytes per session (replies + events)
  int max_pending{16};                             // connections that have not said hello yet
  std::chrono::milliseconds hello_timeout{5'000};  // no valid hello this soon: close
  std::string tls_cert;                            // PEM files; both set: the bridge speaks TLS
  std::string tls_key;
  bool insecure_plaintext{false};        // allow a non-loopback bind without TLS (loud)
  std::string audit_file;                // state-changing ops appended here too ("" = log only)
  std::vector<std::string> status_vars;  // empty: the defaults that exist
  int send_buffer_bytes{0};              // SO_SNDBUF per session; 0: system default (tests)
};

/// The options a config's `bridge:` section gives; `port` overrides bridge.port when set.
ServerOptions options_from_config(const rt::BridgeSpec& spec);

/// Checks what start() would refuse, without binding or starting anything (edmplc --check):
/// the token files (mode, minimum length, distinct), the bind address and its policy (a
/// non-loopback bind needs a token, and TLS or insecure_plaintext), the TLS key's mode.
/// Returns the tokens. Throws BridgeError.
TokenSet validate_options(const ServerOptions& options);

/// Counters since start(). Any thread.
struct ServerStats {
  std::uint64_t sessions_open{0};     // authenticated sessions now
  std::uint64_t sessions_pending{0};  // connections waiting for their hello now
  std::uint64_t pending_evicted{0};   // pre-hello connections closed for a newer one (cap)
  std::uint64_t hello_timeouts{0};    // no valid hello within hello_timeout
  std::uint64_t hello_failures{0};    // wrong token or protocol
  std::uint64_t accept_errors{0};     // accept() failed (e.g. out of descriptors)
  std::uint64_t queue_bytes_peak{0};  // most bytes one session ever had queued
  std::uint64_t sessions_accepted{0};
  std::uint64_t sessions_refused{0};  // a valid hello found no free slot (busy)
  std::uint64_t requests{0};
  std::uint64_t errors{0};
  std::uint64_t events_sent{0};
  std::uint64_t events_dropped{0};    // queue full
  std::uint64_t slow_disconnects{0};  // stalled past stall_timeout
  std::uint64_t timeouts{0};          // read timeouts
  std::uint64_t programs_committed{0};
};

/// Default key variables of the status snapshot (used when present in the registry).
const std::vector<std::string>& default_status_vars();

class Server {
 public:
  Server(rt::Runtime& runtime, ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Loads tokens, checks the bind policy, resolves the status variables, attaches the status
  /// board, trace taps and alarm listener, binds and starts the io thread. Throws BridgeError
  /// (nothing started) on any refusal. Call before Runtime::run().
  void start();
  /// Closes the listener and every session and joins the io thread. Idempotent.
  void stop();

  /// The bound port (after start()).
  [[nodiscard]] std::uint16_t port() const noexcept;
  [[nodiscard]] ServerStats stats() const noexcept;

  /// Hands a connected transport to the server as a new session, as the listener does with
  /// each accepted socket (tests and fuzzing use in-memory transports). Any thread.
  void adopt(std::unique_ptr<Transport> transport);
  /// The io_context the server's thread runs (to make transports for adopt()).
  boost::asio::io_context& io_context() noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace edm::bridge
