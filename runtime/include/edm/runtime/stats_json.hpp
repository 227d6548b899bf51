#pragma once
// The per-task statistics document written by `edmplc --stats-out` (DESIGN.md §4):
// {"tasks": [{"name", "interval_us", "priority", "cycles", "overruns", "omitted_cycles",
//             "exec_us": {min, avg, p50, p99, max}, "latency_us": {min, avg, p50, p99, max}}]}
// Built with nlohmann_json: pretty-printed with a 2-space indent, fields in this order, tasks in
// the given order; microseconds rounded to 3 decimals and printed in their shortest form (250.0,
// 14.123).
//
// Thread safety: pure functions of their arguments (thread-safe).
// RT safety: none of this is RT-safe (allocates, does file I/O); call it from non-RT threads.

#include <string>
#include <vector>

#include "edm/runtime/task_stats.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

struct TaskStatsReport {
  std::string name;
  Duration interval{};
  int priority{0};
  TaskStatsSnapshot stats;
};

/// The JSON document, ending with a newline. Names are escaped (quotes, backslash, control
/// characters); UTF-8 passes through unchanged, an invalid UTF-8 byte becomes U+FFFD.
[[nodiscard]] std::string stats_to_json(const std::vector<TaskStatsReport>& tasks);

/// Writes stats_to_json(tasks) to `path` (created or truncated). Throws std::runtime_error naming
/// the path and the system's reason when the file cannot be opened or written.
void write_stats_json_file(const std::string& path, const std::vector<TaskStatsReport>& tasks);

}  // namespace edm::rt
