#pragma once
// edmplc's intake of NCMD/DCMD (docs/mqtt.md "Commands", docs/security.md "MQTT"): everything a
// broker (or any client publishing through it) sends the machine, from libmosquitto's callback
// to the handler that may write a parameter.
//
//   offer()   libmosquitto's network thread (EdgeNode's command sink): only the topic (exactly
//             this node's NCMD/DCMD), the retain flag and the payload's size are looked at; a
//             message that passes is copied into a bounded inbox (messages and bytes), anything
//             else is counted. Never a decode there.
//   process() the publisher's thread (never an RT thread): each message is screened (metric
//             count, framing; sparkplug/inbound.hpp) before it is decoded, a repeated metric
//             refuses the message, each metric goes to the handler (CommandGate);
//             Node Control/Rebirth is answered by the caller.
//
// Every log line quotes, escapes and caps what came from the broker (rt::log_quote), and is
// rate-limited (rt::LogRateLimiter): a drop is told once per episode (then once per 10 s while it
// lasts) with a count, the command audit 20 lines at once then one per 2 s, the rest counted and
// summed up.
// Thread-safety: offer() from any thread; process(), finish() from one owner thread; the
// counters from any thread.

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

#include "edm/runtime/log_limiter.hpp"
#include "edm/sparkplug/inbound.hpp"
#include "edm/sparkplug/sparkplug.hpp"

namespace edm::telemetry {

enum class CommandOutcome : std::uint8_t {
  kWritten,
  kRefused,     // not allowed (commands off, not listed, …)
  kOutOfRange,  // allowed, but the value does not fit the parameter's type or range
};

/// A command's metric (never Node Control/Rebirth): written or refused, `why` saying why not.
/// Untrusted text in `why` must already be quoted. Called from process().
using CommandHandler = std::function<CommandOutcome(
    sparkplug::MessageType type, const sparkplug::Metric& metric, std::string& why)>;

struct IntakeOptions {
  std::string ncmd_topic;  // exactly this node's (nothing else is read)
  std::string dcmd_topic;
  std::string broker;  // "host:port", for the audit lines
  sparkplug::InboundLimits limits;
  /// Lines: `info` the command audit, `warn` drops. Either may be empty.
  std::function<void(const std::string&)> info;
  std::function<void(const std::string&)> warn;
};

class CommandIntake {
 public:
  using Clock = std::chrono::steady_clock;
  /// Messages the inbox holds at most, and bytes: max(1 MiB, 4 x max_payload_bytes).
  static constexpr std::size_t kInboxMessages = 256;
  /// A kind of drop is told at most once in this long; a quiet one is summed up after it.
  static constexpr std::chrono::seconds kEpisode{10};

  CommandIntake(IntakeOptions options, CommandHandler handler);

  /// A message from the broker (libmosquitto's callback). Copies at most max_payload_bytes.
  void offer(std::string_view topic, std::string_view payload, bool retained);
  /// Handles what was offered since the last call; true when a rebirth was asked for.
  bool process(Clock::time_point now);
  /// Tells what the rate limits held back (a clean stop).
  void finish(Clock::time_point now);

  [[nodiscard]] std::uint64_t accepted() const noexcept { return accepted_.load(); }
  [[nodiscard]] std::uint64_t refused() const noexcept { return refused_.load(); }
  /// Messages dropped unread (topic, retained, size, inbox full, metric count, framing).
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }
  /// Refused metrics whose value did not fit the parameter (also counted in refused()).
  [[nodiscard]] std::uint64_t out_of_range() const noexcept { return out_of_range_.load(); }
  [[nodiscard]] std::size_t inbox_byte_capacity() const noexcept { return inbox_cap_bytes_; }

 private:
  // The kinds of dropped messages; the first four are seen by offer().
  enum Drop : std::uint8_t {
    kForeign,
    kRetained,
    kTooLarge,
    kInboxFull,
    kTooManyMetrics,
    kMalformed,
    kDropCount
  };
  static constexpr std::size_t kOfferDrops = kInboxFull + 1;
  struct Seen {
    std::uint64_t count{0};
    std::size_t bytes{0};  // the first one's
    bool dcmd{false};
    std::string topic;  // the first one's, at most kTopicKept bytes
  };
  struct Message {
    sparkplug::MessageType type{sparkplug::MessageType::kDCmd};
    std::string payload;
  };
  static constexpr std::size_t kTopicKept = 256;

  /// `count` drops of `kind`; `line` says the first (built only when it is told).
  template <class Line>
  void drop_seen(Drop kind, std::uint64_t count, Clock::time_point now, Line line);
  bool handle(const Message& msg, Clock::time_point now);
  void audit(const std::string& key, const std::string& line, Clock::time_point now);
  void sweep(Clock::time_point now, std::chrono::milliseconds quiet);

  IntakeOptions opt_;
  CommandHandler handler_;
  std::size_t inbox_cap_bytes_;

  std::mutex mu_;  // offer() against process()
  std::deque<Message> inbox_;
  std::size_t inbox_bytes_{0};
  std::array<Seen, kOfferDrops> seen_{};

  // Owner thread only (the limiters are thread-safe anyway).
  rt::LogRateLimiter drop_lines_{{.burst = 1.0, .per_s = 0.1, .max_keys = 16}};
  rt::LogRateLimiter audit_lines_{{.burst = 20.0, .per_s = 0.5, .max_keys = 16}};
  std::array<std::uint64_t, kDropCount> untold_{};  // drops not told since the last line

  std::atomic<std::uint64_t> accepted_{0}, refused_{0}, dropped_{0}, out_of_range_{0};
};

}  // namespace edm::telemetry
