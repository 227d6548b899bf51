#include "edm/runtime/stats_json.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <iterator>
#include <stdexcept>
#include <system_error>

namespace edm::rt {
namespace {

void append_escaped(std::string& out, const std::string& text) {
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          fmt::format_to(std::back_inserter(out), "\\u{:04x}", static_cast<unsigned char>(c));
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

void append_summary(std::string& out, const char* key, const DurationSummary& s) {
  fmt::format_to(std::back_inserter(out),
                 "      \"{}\": {{\n"
                 "        \"min\": {:.3f},\n"
                 "        \"avg\": {:.3f},\n"
                 "        \"p50\": {:.3f},\n"
                 "        \"p99\": {:.3f},\n"
                 "        \"max\": {:.3f}\n"
                 "      }}",
                 key, s.min_us, s.avg_us, s.p50_us, s.p99_us, s.max_us);
}

[[noreturn]] void throw_io_error(const std::string& path, const char* what, int error) {
  throw std::runtime_error(fmt::format("cannot {} stats file '{}': {}", what, path,
                                       std::generic_category().message(error)));
}

}  // namespace

std::string stats_to_json(const std::vector<TaskStatsReport>& tasks) {
  std::string out = "{\n  \"tasks\": [";
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskStatsReport& t = tasks[i];
    out += i == 0 ? "\n    {\n      \"name\": " : ",\n    {\n      \"name\": ";
    append_escaped(out, t.name);
    fmt::format_to(std::back_inserter(out),
                   ",\n"
                   "      \"interval_us\": {:.3f},\n"
                   "      \"priority\": {},\n"
                   "      \"cycles\": {},\n"
                   "      \"overruns\": {},\n"
                   "      \"omitted_cycles\": {},\n",
                   to_micros(t.interval), t.priority, t.stats.cycles, t.stats.overruns,
                   t.stats.omitted_cycles);
    append_summary(out, "exec_us", t.stats.exec);
    out += ",\n";
    append_summary(out, "latency_us", t.stats.latency);
    out += "\n    }";
  }
  out += tasks.empty() ? "]\n}\n" : "\n  ]\n}\n";
  return out;
}

void write_stats_json_file(const std::string& path, const std::vector<TaskStatsReport>& tasks) {
  const std::string text = stats_to_json(tasks);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    throw_io_error(path, "open", errno);
  }
  const std::size_t written = std::fwrite(text.data(), 1, text.size(), file);
  const int write_error = written == text.size() ? 0 : errno;
  // fclose flushes: a full disk often shows up only here.
  const bool closed = std::fclose(file) == 0;
  const int close_error = errno;
  if (write_error != 0 || written != text.size()) {
    throw_io_error(path, "write", write_error != 0 ? write_error : EIO);
  }
  if (!closed) {
    throw_io_error(path, "write", close_error);
  }
}

}  // namespace edm::rt
