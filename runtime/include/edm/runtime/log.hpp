#pragma once
// Logging for the runtime's non-RT code: spdlog, made asynchronous by init_logging() so that a
// slow terminal never stalls a caller for long.
//
// RT threads never log. What they have to say travels as data: alarms through the machine's
// alarm queue (machine.hpp, logged by the controlling thread), figures through the task
// statistics and the trace recorder.
//
// Non-RT: both functions (they allocate, start or join spdlog's worker, take a lock).
// Thread-safe: both functions.

#include <spdlog/common.h>

namespace edm::rt {

/// Non-RT, idempotent: makes an asynchronous spdlog logger (colored stderr, pattern with time and
/// level) the default logger and sets its level. A second call only changes the level.
void init_logging(spdlog::level::level_enum level = spdlog::level::info);

/// Non-RT, idempotent: flushes and stops the asynchronous logger. spdlog keeps working afterwards
/// through a synchronous stderr logger, so late messages (e.g. from destructors) are not lost.
void shutdown_logging();

}  // namespace edm::rt
