#pragma once
// Parsing and statistics for the jitter bench driver (jitter_bench.cpp): cyclictest's histogram
// output (`-h N`), edmplc's --stats-out JSON, duration arguments and the pooling median.
// Non-RT (allocates); every function is pure, so thread-safe.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace edm::bench {

/// Release latency of one run, in microseconds.
struct RunStats {
  std::uint64_t cycles{0};
  double p50_us{0.0};
  double p99_us{0.0};
  double max_us{0.0};
  std::uint64_t overruns{0};        // edmplc only
  std::uint64_t omitted_cycles{0};  // edmplc only
  std::int64_t interval_us{0};      // edmplc only: the task's period as it reports it
};

/// Parses a whole non-negative decimal number (leading zeros allowed: cyclictest pads with them).
inline std::optional<std::uint64_t> parse_uint(std::string_view text) {
  std::uint64_t value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc{} || ptr != end) {
    return std::nullopt;
  }
  return value;
}

/// A --duration argument in whole seconds: "10", "10s" or "2m" (cyclictest's -D takes whole
/// seconds, so finer units are refused rather than rounded). Between 1 s and 24 h.
inline std::optional<int> parse_seconds(std::string_view text) {
  std::uint64_t scale = 1;
  if (text.ends_with("m")) {
    scale = 60;
    text.remove_suffix(1);
  } else if (text.ends_with("s") && !text.ends_with("ms") && !text.ends_with("us")) {
    text.remove_suffix(1);
  }
  const auto value = parse_uint(text);
  if (!value || *value == 0 || *value > 24 * 3600 / scale) {
    return std::nullopt;
  }
  return static_cast<int>(*value * scale);
}

/// Median (the mean of the two middle values for an even count); 0 for an empty list.
inline double median(std::vector<double> values) {
  if (values.empty()) {
    return 0.0;
  }
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  return values.size() % 2 == 1 ? values[mid] : (values[mid - 1] + values[mid]) / 2.0;
}

/// cyclictest's `-h N` report for one thread. Bucket k counts latencies in [k, k+1) us:
/// cyclictest truncates each latency to whole microseconds before bucketing it.
struct CyclictestReport {
  std::vector<std::uint64_t> buckets;  // index = latency in whole us
  std::uint64_t bucketed{0};           // "# Total:" (samples inside the histogram)
  std::uint64_t overflows{0};          // "# Histogram Overflows:" (samples >= N us)
  std::uint64_t min_us{0};
  std::uint64_t max_us{0};  // truncated to whole us, like every cyclictest value

  [[nodiscard]] std::uint64_t samples() const { return bucketed + overflows; }

  /// Latency (us) at quantile q: the upper edge (k + 1) of the bucket holding the
  /// ceil(q * samples)-th smallest sample, the same conservative convention as edmplc's
  /// LatencyHistogram::quantile(). A rank that falls among the overflows answers max_us.
  [[nodiscard]] double quantile_us(double q) const {
    const std::uint64_t n = samples();
    if (n == 0) {
      return 0.0;
    }
    auto rank =
        static_cast<std::uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(n)));
    rank = std::clamp<std::uint64_t>(rank, 1, n);
    std::uint64_t seen = 0;
    for (std::size_t k = 0; k < buckets.size(); ++k) {
      seen += buckets[k];
      if (seen >= rank) {
        return static_cast<double>(k + 1);
      }
    }
    return static_cast<double>(max_us);
  }

  [[nodiscard]] RunStats stats() const {
    RunStats s;
    s.cycles = samples();
    s.p50_us = quantile_us(0.50);
    s.p99_us = quantile_us(0.99);
    s.max_us = static_cast<double>(max_us);
    return s;
  }
};

/// Parses cyclictest's stdout for `-q -t 1 -h N`: histogram lines "000012 000531" and the
/// "# Total:", "# Min Latencies:", "# Max Latencies:", "# Histogram Overflows:" lines. Other
/// lines ("# Histogram", "# /dev/cpu_dma_latency set to 0us", "# Thread 0: …") are ignored.
/// On failure returns nullopt and says why in `error`.
inline std::optional<CyclictestReport> parse_cyclictest(std::string_view out, std::string& error) {
  CyclictestReport report;
  bool have_total = false;
  bool have_max = false;
  bool have_overflows = false;
  std::size_t line_no = 0;
  auto fields = [](std::string_view line) {
    std::vector<std::string_view> result;
    std::size_t pos = 0;
    while (pos < line.size()) {
      const std::size_t start = line.find_first_not_of(" \t", pos);
      if (start == std::string_view::npos) {
        break;
      }
      const std::size_t stop = std::min(line.find_first_of(" \t", start), line.size());
      result.push_back(line.substr(start, stop - start));
      pos = stop;
    }
    return result;
  };
  auto summary = [&](std::string_view line, std::string_view key, std::uint64_t& value) {
    if (!line.starts_with(key)) {
      return false;
    }
    const auto words = fields(line.substr(key.size()));
    const auto parsed = words.size() == 1 ? parse_uint(words[0]) : std::nullopt;
    if (!parsed) {
      error = "line " + std::to_string(line_no) + ": expected one thread's value after '" +
              std::string(key) + "' (the driver runs cyclictest with -t 1)";
      return false;
    }
    value = *parsed;
    return true;
  };
  while (!out.empty()) {
    const std::size_t eol = std::min(out.find('\n'), out.size());
    std::string_view line = out.substr(0, eol);
    out.remove_prefix(std::min(eol + 1, out.size()));
    ++line_no;
    if (!line.empty() && line.back() == '\r') {
      line.remove_suffix(1);
    }
    if (!line.empty() && line[0] >= '0' && line[0] <= '9') {
      const auto words = fields(line);
      const auto bucket = words.size() == 2 ? parse_uint(words[0]) : std::nullopt;
      const auto count = words.size() == 2 ? parse_uint(words[1]) : std::nullopt;
      if (!bucket || !count || *bucket != report.buckets.size()) {
        error = "line " + std::to_string(line_no) +
                ": not a one-thread histogram line in order: '" + std::string(line) + "'";
        return std::nullopt;
      }
      report.buckets.push_back(*count);
      continue;
    }
    std::uint64_t ignored_avg = 0;
    const bool known = summary(line, "# Total:", report.bucketed) ||
                       summary(line, "# Min Latencies:", report.min_us) ||
                       summary(line, "# Avg Latencies:", ignored_avg) ||
                       summary(line, "# Max Latencies:", report.max_us) ||
                       summary(line, "# Histogram Overflows:", report.overflows);
    if (!error.empty()) {
      return std::nullopt;
    }
    if (known) {
      have_total = have_total || line.starts_with("# Total:");
      have_max = have_max || line.starts_with("# Max Latencies:");
      have_overflows = have_overflows || line.starts_with("# Histogram Overflows:");
    }
  }
  if (report.buckets.empty() || !have_total || !have_max || !have_overflows) {
    error =
        "no complete histogram (need histogram lines, '# Total:', '# Max Latencies:' and "
        "'# Histogram Overflows:'; was cyclictest run with -h?)";
    return std::nullopt;
  }
  std::uint64_t sum = 0;
  for (const std::uint64_t c : report.buckets) {
    sum += c;
  }
  if (sum != report.bucketed) {
    error = "histogram lines add up to " + std::to_string(sum) + " but '# Total:' says " +
            std::to_string(report.bucketed);
    return std::nullopt;
  }
  if (report.samples() == 0) {
    error = "cyclictest recorded no cycles";
    return std::nullopt;
  }
  return report;
}

/// Reads edmplc's --stats-out JSON and returns the release latency of the highest-priority task
/// (lowest priority number; the first one on a tie): the task the bench configs measure.
inline std::optional<RunStats> parse_edmplc_stats(std::string_view json_text, std::string& error) {
  const auto doc = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("tasks") ||
      !doc["tasks"].is_array() || doc["tasks"].empty()) {
    error = "not a stats document with a non-empty \"tasks\" array";
    return std::nullopt;
  }
  const nlohmann::json* best = nullptr;
  for (const auto& task : doc["tasks"]) {
    if (!task.is_object() || !task.contains("priority") || !task["priority"].is_number()) {
      error = "a task without a numeric \"priority\"";
      return std::nullopt;
    }
    if (best == nullptr || task["priority"].get<double>() < (*best)["priority"].get<double>()) {
      best = &task;
    }
  }
  const nlohmann::json& task = *best;
  auto number = [&](const nlohmann::json& obj, const char* key) -> std::optional<double> {
    if (!obj.is_object() || !obj.contains(key) || !obj[key].is_number()) {
      if (error.empty()) {
        error = "task " + task.value("name", std::string("?")) + ": missing number \"" + key + "\"";
      }
      return std::nullopt;
    }
    return obj[key].get<double>();
  };
  const auto cycles = number(task, "cycles");
  const auto overruns = number(task, "overruns");
  const auto omitted = number(task, "omitted_cycles");
  const auto interval = number(task, "interval_us");
  if (!cycles || !overruns || !omitted || !interval || !task.contains("latency_us")) {
    if (error.empty()) {
      error = "task " + task.value("name", std::string("?")) + ": missing \"latency_us\"";
    }
    return std::nullopt;
  }
  const nlohmann::json& latency = task["latency_us"];
  const auto p50 = number(latency, "p50");
  const auto p99 = number(latency, "p99");
  const auto max = number(latency, "max");
  if (!p50 || !p99 || !max) {
    return std::nullopt;
  }
  RunStats s;
  s.cycles = static_cast<std::uint64_t>(*cycles);
  s.overruns = static_cast<std::uint64_t>(*overruns);
  s.omitted_cycles = static_cast<std::uint64_t>(*omitted);
  s.interval_us = std::llround(*interval);
  s.p50_us = *p50;
  s.p99_us = *p99;
  s.max_us = *max;
  return s;
}

}  // namespace edm::bench
