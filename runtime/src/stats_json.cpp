#include "edm/runtime/stats_json.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

namespace edm::rt {
namespace {

using OrderedJson = nlohmann::ordered_json;  // fields in the documented order

// The value printed with 3 decimals, as a number: JSON prints it shortest (250.0, 14.123), so
// the document carries exactly the 3-decimal values.
double round3(double x) {
  const std::string text = fmt::format("{:.3f}", x);
  double value = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), value);  // nan and inf too
  return value;
}

OrderedJson summary(const DurationSummary& s) {
  return {{"min", round3(s.min_us)},
          {"avg", round3(s.avg_us)},
          {"p50", round3(s.p50_us)},
          {"p99", round3(s.p99_us)},
          {"max", round3(s.max_us)}};
}

[[noreturn]] void throw_io_error(const std::string& path, const char* what, int error) {
  throw std::runtime_error(fmt::format("cannot {} stats file '{}': {}", what, path,
                                       std::generic_category().message(error)));
}

}  // namespace

std::string stats_to_json(const std::vector<TaskStatsReport>& tasks) {
  OrderedJson list = OrderedJson::array();
  for (const TaskStatsReport& t : tasks) {
    list.push_back({{"name", t.name},
                    {"interval_us", round3(to_micros(t.interval))},
                    {"priority", t.priority},
                    {"cycles", t.stats.cycles},
                    {"overruns", t.stats.overruns},
                    {"omitted_cycles", t.stats.omitted_cycles},
                    {"exec_us", summary(t.stats.exec)},
                    {"latency_us", summary(t.stats.latency)}});
  }
  const OrderedJson doc = {{"tasks", std::move(list)}};
  // Invalid UTF-8 in a name becomes U+FFFD instead of an exception: the document stays JSON.
  return doc.dump(2, ' ', /*ensure_ascii=*/false, OrderedJson::error_handler_t::replace) + "\n";
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
