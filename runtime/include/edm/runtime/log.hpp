#pragma once
// Logging for the runtime: spdlog for non-RT code, a lock-free record queue for RT threads.
//
// Non-RT code calls spdlog directly (spdlog::info(...)). After init_logging() the default logger
// is asynchronous, so a slow terminal never stalls a caller for long.
//
// RT threads call rt_log(): it copies a fixed-size record (level, time, two string pointers, four
// doubles) into a bounded lock-free MPMC queue and returns; a non-RT drain thread formats the
// records and forwards them to spdlog. A full queue drops the record and counts it.
// The queue is a fixed array (1024 records) allocated at start-up; nothing allocates afterwards.
//
// RT-safe: rt_log(), rt_log_dropped(), RtLogQueue::push(), RtLogQueue::dropped().
// Non-RT: everything else (init/shutdown allocate, start or join threads, take locks).
// Thread-safe: every function here. RtLogQueue::push() may be called from any number of threads;
// pop()/drain() from any number of threads too, but records are only in per-producer order when a
// single consumer drains.

#include <spdlog/common.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "edm/runtime/time.hpp"

namespace edm::rt {

/// Severity of an RT log record; the numbers match spdlog::level::level_enum.
enum class RtLogLevel : std::uint8_t {
  kTrace = 0,
  kDebug = 1,
  kInfo = 2,
  kWarn = 3,
  kError = 4,
  kCritical = 5,
};

/// One RT log record. Trivially copyable so that pushing it is a plain copy.
/// `source` and `fmt` are stored as pointers and read later by the drain thread: they must be
/// string literals or strings that outlive the runtime (never a std::string's c_str()).
struct RtLogRecord {
  RtLogLevel level{RtLogLevel::kInfo};
  TimePoint t{0};               // CLOCK_MONOTONIC at the rt_log() call
  const char* source{nullptr};  // e.g. the task or block name; may be null
  const char* fmt{nullptr};     // fmt-style format string; the args are doubles ("{:.3f}", "{}")
  std::array<double, 4> args{};
};

/// A bounded lock-free multi-producer queue of RtLogRecord with a drop counter.
/// The global instance behind rt_log() is one of these; tests make their own.
class RtLogQueue {
 public:
  /// Records the queue holds before it starts dropping.
  static constexpr std::size_t kCapacity = 1024;

  /// Non-RT: allocates all node storage up front; push/pop never allocate afterwards.
  RtLogQueue();
  ~RtLogQueue();
  RtLogQueue(const RtLogQueue&) = delete;
  RtLogQueue& operator=(const RtLogQueue&) = delete;

  /// Enqueues a copy of rec. Returns false (and counts a drop) if the queue is full.
  /// RT-safe: lock-free, no allocation, never blocks. Any number of producer threads.
  bool push(const RtLogRecord& rec) noexcept;

  /// Dequeues the oldest record into out; false if empty, or if the next record is still being
  /// written by a producer (it shows up on a later call). Never waits; normally non-RT.
  bool pop(RtLogRecord& out) noexcept;

  /// Non-RT: pops at most max_records queued records and calls fn(const RtLogRecord&) for each,
  /// in queue order. The bound keeps one call finite while producers keep pushing.
  /// Returns the number of records handed to fn.
  template <class Fn>
  std::size_t drain(Fn&& fn, std::size_t max_records = kCapacity) {
    std::size_t n = 0;
    RtLogRecord rec;
    while (n < max_records && pop(rec)) {
      fn(static_cast<const RtLogRecord&>(rec));
      ++n;
    }
    return n;
  }

  /// Records dropped because the queue was full, since construction. RT-safe, any thread.
  [[nodiscard]] std::uint64_t dropped() const noexcept {
    return dropped_.load(std::memory_order_relaxed);
  }

 private:
  struct Impl;  // the ring (about 72 KiB), allocated once by the constructor
  std::unique_ptr<Impl> impl_;
  std::atomic<std::uint64_t> dropped_{0};
};

/// The message text of a record: fmt::format(rec.fmt, args...) (unused args are ignored). A bad
/// format string never throws: the raw format string is returned with a note. Non-RT.
[[nodiscard]] std::string format_rt_log_message(const RtLogRecord& rec);

/// Non-RT, idempotent: makes an asynchronous spdlog logger (colored stderr, pattern with time and
/// level) the default logger, sets its level (also the threshold below which rt_log() discards
/// records), and starts the thread that drains rt_log() records into it. A second call only
/// changes the level.
void init_logging(spdlog::level::level_enum level = spdlog::level::info);

/// Non-RT, idempotent: stops the RT drain thread, forwards the records still queued, flushes and
/// stops the asynchronous logger. spdlog keeps working afterwards through a synchronous stderr
/// logger, so late messages (e.g. from destructors) are not lost.
void shutdown_logging();

/// Logs from an RT thread: queues {level, now, source, fmt, a..d} and returns. Records below the
/// level given to init_logging() (info before it is called) are discarded at once.
/// `source` and `fmt` must be string literals or outlive the runtime (they are read later).
/// Formatting happens on the drain thread with fmt, so all arguments are doubles: use "{}" or
/// "{:.3f}", not "{:d}" (a bad format is logged raw, never thrown).
/// RT-safe: lock-free, no allocation, never blocks; a full queue drops the record and counts it.
void rt_log(RtLogLevel level, const char* source, const char* fmt, double a = 0, double b = 0,
            double c = 0, double d = 0) noexcept;

/// Records rt_log() dropped because its queue was full, since start-up. RT-safe, any thread.
[[nodiscard]] std::uint64_t rt_log_dropped() noexcept;

/// Non-RT: drains the global rt_log() queue synchronously, appending one line per record,
/// "<level> [<source>] <message>" (spdlog's level names), to out. Returns the number of records.
/// For tests and tools that run without init_logging(); while the drain thread runs it competes
/// for the same records.
std::size_t drain_rt_log_for_test(std::vector<std::string>& out);

}  // namespace edm::rt
