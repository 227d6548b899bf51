#pragma once
// Client library of the HMI bridge (docs/protocol.md), used by edmhmi and the tests. It links
// the protocol and Boost.Asio only — never the runtime.
//
//   edm::bridge::Client c;
//   c.connect({.host = "127.0.0.1", .port = 7730, .token = token});   // TCP + hello
//   auto r = c.request("status");                                      // sync, with timeout
//   c.set_event_handler([](const Json& ev) { ... });                   // status/alarm/... events
//   c.subscribe({"status", "alarm"}, 50);
//   auto up = c.upload_program(blocks);                                // begin/chunk/commit
//
// Threads: the client runs one internal I/O thread. Every public member is thread-safe and may
// be called from any thread except the handlers' own (request() from inside an event handler
// would wait for a reply the same thread has to read: it returns a "deadlock" transport error).
// Event and connection handlers run on the I/O thread: keep them short.
// Reconnect: reconnect() re-dials, says hello again and replays the subscriptions and the trace;
// with ClientOptions::auto_reconnect a background thread does that after a lost connection,
// with exponential back-off. Requests in flight when the connection drops fail (not retried).

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "edm/bridge/codec.hpp"
#include "edm/bridge/protocol.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::bridge {

/// TLS to the bridge (docs/security.md). The server is verified either against a CA file (its
/// chain, and that it names the host dialled) or by the SHA-256 fingerprint of its certificate
/// (`openssl x509 -in cert.pem -noout -fingerprint -sha256`; colons and case do not matter).
struct ClientTls {
  bool enabled{false};
  std::string ca_file;
  std::string fingerprint;
};

/// "AB:CD:…" → "abcd…".
std::string normalise_fingerprint(std::string_view text);

struct ClientOptions {
  std::string host{"127.0.0.1"};
  std::uint16_t port{kDefaultPort};
  std::string token;
  /// A relaying HMI (edmhmi serve): the end client's address as it saw it, sent as hello's
  /// "peer" so edmplc throttles failed log-ins per browser (docs/protocol.md). Empty: not sent.
  /// At most kMaxHelloPeerChars printable ASCII characters, else the hello is refused.
  std::string peer;
  std::chrono::milliseconds timeout{5000};     // connect, hello, and default request timeout
  std::chrono::milliseconds keepalive{20000};  // ping when idle this long (server read timeout)
  bool auto_reconnect{false};
  std::chrono::milliseconds reconnect_min{100};
  std::chrono::milliseconds reconnect_max{5000};
  std::size_t max_line_bytes{64u << 20};  // longest reply/event accepted
  ClientTls tls;
};

/// program.begin's options (docs/protocol.md).
struct UploadOptions {
  std::size_t chunk_blocks{4096};
  /// "main" or "mdi"; empty = the server's default (main), the field is then not sent.
  std::string slot;
  /// The offset.get generation the blocks were interpreted with: cycle.start refuses the program
  /// once the work offsets have changed since. Absent: not checked.
  std::optional<std::uint64_t> offsets_generation;
};

/// Could not connect or the hello was refused. what() says why (with the server's error code).
class ClientError : public std::runtime_error {
 public:
  ClientError(const std::string& what, std::optional<ErrorCode> code = std::nullopt)
      : std::runtime_error(what), code_(code) {}
  [[nodiscard]] std::optional<ErrorCode> code() const noexcept { return code_; }

 private:
  std::optional<ErrorCode> code_;
};

/// A reply. ok: the server said ok (body = the whole reply object). Otherwise either the server
/// refused (code set, message, details) or the transport failed (code empty: timeout,
/// disconnected, not connected — message says which).
struct Reply {
  bool ok{false};
  Json body;
  std::optional<ErrorCode> code;
  std::string message;
  Json details;
  explicit operator bool() const noexcept { return ok; }
};

class Client {
 public:
  using EventHandler = std::function<void(const Json& event)>;
  using ConnectionHandler = std::function<void(bool connected)>;

  Client();
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Connects and says hello. Returns the role. Throws ClientError.
  Role connect(const ClientOptions& options);
  /// Closes the connection (and stops auto-reconnect). Idempotent.
  void close();
  [[nodiscard]] bool connected() const noexcept;
  [[nodiscard]] Role role() const noexcept;

  /// Sends {"id", "op", ...params} and waits for the reply (default timeout: options.timeout).
  Reply request(std::string_view op, const Json& params = Json::object(),
                std::optional<std::chrono::milliseconds> timeout = std::nullopt);
  /// Sends a raw line (tests: malformed JSON, huge lines) and waits for the next reply without
  /// an id or with `expect_id`. The line must not contain '\n' (it is appended).
  Reply request_raw(std::string line, std::optional<std::int64_t> expect_id = std::nullopt,
                    std::optional<std::chrono::milliseconds> timeout = std::nullopt);

  void set_event_handler(EventHandler h);
  void set_connection_handler(ConnectionHandler h);

  /// subscribe {topics, rate_hz}; remembered and replayed on reconnect.
  Reply subscribe(const std::vector<std::string>& topics, int rate_hz = 10);
  Reply unsubscribe();
  /// trace.start {vars} / trace.stop; remembered and replayed on reconnect.
  Reply trace_start(const std::vector<std::string>& vars);
  Reply trace_stop();

  /// program.begin / program.chunk × n / program.commit with the CRC-32 checksum. Returns the
  /// commit's reply, or the first failed one (then program.abort is sent).
  Reply upload_program(std::span<const machining::MotionBlock> blocks,
                       std::size_t chunk_blocks = 4096);
  /// The same with program.begin's options: the slot, the work-offset generation.
  Reply upload_program(std::span<const machining::MotionBlock> blocks,
                       const UploadOptions& options);

  /// Closes and connects again with the last options, then replays subscriptions and trace.
  /// Throws ClientError like connect().
  Role reconnect();
  /// Connections made so far (1 after the first connect()).
  [[nodiscard]] std::uint64_t connections() const noexcept;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace edm::bridge
