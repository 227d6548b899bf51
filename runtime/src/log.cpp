#include "edm/runtime/log.hpp"

#include <fmt/format.h>
#include <spdlog/async.h>
#include <spdlog/async_logger.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <time.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>

#include "edm/runtime/mpmc_queue.hpp"

namespace edm::rt {

static_assert(std::is_trivially_copyable_v<RtLogRecord>, "RT log records are copied as bytes");

// The ring lives on the heap (about 72 KiB): MpmcQueue (mpmc_queue.hpp) says why not Boost's.
struct RtLogQueue::Impl : MpmcQueue<RtLogRecord, RtLogQueue::kCapacity> {};

RtLogQueue::RtLogQueue() : impl_(std::make_unique<Impl>()) {}
RtLogQueue::~RtLogQueue() = default;

bool RtLogQueue::push(const RtLogRecord& rec) noexcept {
  if (impl_->push(rec)) {
    return true;
  }
  dropped_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool RtLogQueue::pop(RtLogRecord& out) noexcept { return impl_->pop(out); }

std::string format_rt_log_message(const RtLogRecord& rec) {
  const char* f = rec.fmt != nullptr ? rec.fmt : "";
  try {
    return fmt::format(fmt::runtime(f), rec.args[0], rec.args[1], rec.args[2], rec.args[3]);
  } catch (const fmt::format_error& e) {
    // The format string comes from code, not data: show it raw so the bug is visible and fixable.
    return fmt::format("{} [bad format: {}; args {}, {}, {}, {}]", f, e.what(), rec.args[0],
                       rec.args[1], rec.args[2], rec.args[3]);
  }
}

namespace {

constexpr std::size_t kAsyncQueueSize = 8192;  // spdlog's own queue (non-RT producers block)
constexpr auto kDrainPoll = std::chrono::milliseconds(2);
constexpr int kFinalDrainPasses = 8;  // bounds shutdown if a producer is still pushing
constexpr const char* kPattern = "%Y-%m-%d %H:%M:%S.%f [%^%l%$] %v";

RtLogQueue& global_queue() noexcept {
  static RtLogQueue queue;
  return queue;
}
// Constructs the queue during static initialisation, so the first rt_log() never allocates.
[[maybe_unused]] RtLogQueue& g_queue_at_startup = global_queue();

std::atomic<int> g_rt_min_level{static_cast<int>(RtLogLevel::kInfo)};

TimePoint monotonic_now() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return TimePoint{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

spdlog::level::level_enum to_spdlog(RtLogLevel level) noexcept {
  const auto n = static_cast<int>(level);
  return n > static_cast<int>(spdlog::level::critical) ? spdlog::level::critical
                                                       : static_cast<spdlog::level::level_enum>(n);
}

std::string with_source(const RtLogRecord& rec) {
  if (rec.source == nullptr) {
    return format_rt_log_message(rec);
  }
  return fmt::format("[{}] {}", rec.source, format_rt_log_message(rec));
}

// Forwards the queued RT records to logger, stamped with the wall time at which rt_log() ran,
// and reports the drop count when it has grown. Returns the number of records forwarded.
std::size_t forward_rt_records(spdlog::logger& logger, std::uint64_t& reported_drops) {
  RtLogQueue& queue = global_queue();
  const auto wall_now = spdlog::log_clock::now();
  const TimePoint mono_now = monotonic_now();
  const std::size_t n = queue.drain([&](const RtLogRecord& rec) {
    const auto wall =
        wall_now - std::chrono::duration_cast<spdlog::log_clock::duration>(mono_now - rec.t);
    logger.log(wall, spdlog::source_loc{}, to_spdlog(rec.level), with_source(rec));
  });
  const std::uint64_t dropped = queue.dropped();
  if (dropped != reported_drops) {
    logger.warn("rt_log: {} record(s) dropped since start-up (queue of {} full)", dropped,
                RtLogQueue::kCapacity);
    reported_drops = dropped;
  }
  return n;
}

void drain_loop(std::shared_ptr<spdlog::logger> logger, const std::atomic<bool>& stop,
                std::uint64_t& reported_drops) {
  while (!stop.load(std::memory_order_acquire)) {
    std::size_t n = 0;
    try {
      n = forward_rt_records(*logger, reported_drops);
    } catch (const std::exception& e) {
      // Only allocation can fail here; keep the thread alive rather than terminate the process.
      logger->error("rt_log drain: {}", e.what());
    }
    if (n == 0) {
      std::this_thread::sleep_for(kDrainPoll);  // non-RT thread: a short poll, no busy spin
    }
  }
}

struct LoggingState {
  std::mutex mutex;
  std::shared_ptr<spdlog::details::thread_pool> pool;
  std::shared_ptr<spdlog::logger> logger;  // the async logger while logging is initialised
  std::thread drain_thread;
  std::atomic<bool> stop{false};
  std::uint64_t reported_drops{0};  // touched by the drain thread, or under mutex once joined

  ~LoggingState() {
    // A program that forgot shutdown_logging() must still exit without std::terminate.
    if (drain_thread.joinable()) {
      stop.store(true, std::memory_order_release);
      drain_thread.join();
    }
  }
};

LoggingState& logging_state() {
  static LoggingState state;
  return state;
}

std::shared_ptr<spdlog::logger> make_sync_stderr_logger(spdlog::level::level_enum level) {
  auto logger = std::make_shared<spdlog::logger>(
      "edm", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  logger->set_pattern(kPattern);
  logger->set_level(level);
  return logger;
}

}  // namespace

void init_logging(spdlog::level::level_enum level) {
  LoggingState& s = logging_state();
  std::lock_guard lock(s.mutex);
  g_rt_min_level.store(static_cast<int>(level), std::memory_order_relaxed);
  if (s.logger) {
    s.logger->set_level(level);
    return;
  }
  s.pool = std::make_shared<spdlog::details::thread_pool>(kAsyncQueueSize, 1);
  auto logger = std::make_shared<spdlog::async_logger>(
      "edm", std::make_shared<spdlog::sinks::stderr_color_sink_mt>(), s.pool,
      spdlog::async_overflow_policy::block);
  logger->set_pattern(kPattern);
  logger->set_level(level);
  logger->flush_on(spdlog::level::warn);
  spdlog::set_default_logger(logger);
  s.logger = logger;
  s.stop.store(false, std::memory_order_release);
  s.drain_thread = std::thread(drain_loop, logger, std::cref(s.stop), std::ref(s.reported_drops));
}

void shutdown_logging() {
  LoggingState& s = logging_state();
  std::lock_guard lock(s.mutex);
  if (!s.logger) {
    return;
  }
  s.stop.store(true, std::memory_order_release);
  if (s.drain_thread.joinable()) {
    s.drain_thread.join();
  }
  for (int pass = 0; pass < kFinalDrainPasses; ++pass) {
    if (forward_rt_records(*s.logger, s.reported_drops) == 0) {
      break;
    }
  }
  spdlog::set_default_logger(make_sync_stderr_logger(s.logger->level()));
  s.logger->flush();
  s.logger.reset();
  // The pool is the last owner of the worker: destroying it writes what is queued, then joins.
  s.pool.reset();
}

void rt_log(RtLogLevel level, const char* source, const char* fmt, double a, double b, double c,
            double d) noexcept {
  if (static_cast<int>(level) < g_rt_min_level.load(std::memory_order_relaxed)) {
    return;
  }
  global_queue().push(RtLogRecord{level, monotonic_now(), source, fmt, {a, b, c, d}});
}

std::uint64_t rt_log_dropped() noexcept { return global_queue().dropped(); }

std::size_t drain_rt_log_for_test(std::vector<std::string>& out) {
  return global_queue().drain([&out](const RtLogRecord& rec) {
    out.push_back(fmt::format("{} {}", spdlog::level::to_string_view(to_spdlog(rec.level)),
                              with_source(rec)));
  });
}

}  // namespace edm::rt
