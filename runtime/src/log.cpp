#include "edm/runtime/log.hpp"

#include <spdlog/async.h>
#include <spdlog/async_logger.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstddef>
#include <memory>
#include <mutex>

namespace edm::rt {

namespace {

constexpr std::size_t kAsyncQueueSize = 8192;  // spdlog's own queue (non-RT producers block)
constexpr const char* kPattern = "%Y-%m-%d %H:%M:%S.%f [%^%l%$] %v";

struct LoggingState {
  std::mutex mutex;
  std::shared_ptr<spdlog::details::thread_pool> pool;
  std::shared_ptr<spdlog::logger> logger;  // the async logger while logging is initialised
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
}

void shutdown_logging() {
  LoggingState& s = logging_state();
  std::lock_guard lock(s.mutex);
  if (!s.logger) {
    return;
  }
  spdlog::set_default_logger(make_sync_stderr_logger(s.logger->level()));
  s.logger->flush();
  s.logger.reset();
  // The pool is the last owner of the worker: destroying it writes what is queued, then joins.
  s.pool.reset();
}

}  // namespace edm::rt
