#include "edm/runtime/trace.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cerrno>
#include <chrono>
#include <exception>
#include <iterator>
#include <stdexcept>
#include <system_error>

namespace edm::rt {

namespace {

constexpr auto kWriterPeriod = std::chrono::milliseconds(5);
constexpr std::int64_t kNsPerSecond = 1'000'000'000;

// RFC 4180 quoting, so an odd variable or task name cannot shift the columns.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) {
    return s;
  }
  std::string quoted = "\"";
  for (char ch : s) {
    if (ch == '"') {
      quoted += '"';
    }
    quoted += ch;
  }
  quoted += '"';
  return quoted;
}

// Integer seconds + 9-digit fraction from the integer ns: exact, and identical on every run.
void append_seconds(std::string& out, TimePoint t) {
  const std::int64_t ns = t.count();
  const std::uint64_t mag =
      ns < 0 ? static_cast<std::uint64_t>(-(ns + 1)) + 1 : static_cast<std::uint64_t>(ns);
  const auto per_s = static_cast<std::uint64_t>(kNsPerSecond);
  fmt::format_to(std::back_inserter(out), "{}{}.{:09}", ns < 0 ? "-" : "", mag / per_s,
                 mag % per_s);
}

}  // namespace

struct TraceRecorder::Channel {
  Channel(std::uint32_t channel_id, std::string task, std::size_t first, std::size_t capacity)
      : id(channel_id), task_name(std::move(task)), first_column(first), ring(capacity) {}

  const std::uint32_t id;
  const std::string task_name;  // already CSV-quoted if needed
  const std::size_t first_column;
  PinSampler sampler;
  std::vector<std::string> column_names;  // already CSV-quoted if needed

  boost::lockfree::spsc_queue<TraceSample> ring;
  std::atomic<std::uint64_t> dropped{0};

  // Consumer side, only under drain_mutex_: the next sample of this channel in the merge.
  TraceSample head{};
  bool has_head{false};
  std::size_t remaining{0};
};

TraceRecorder::TraceRecorder() = default;

TraceRecorder::~TraceRecorder() {
  try {
    stop();
  } catch (const std::exception& e) {
    spdlog::error("trace: {}", e.what());  // only allocation can fail in stop()
  }
}

std::uint32_t TraceRecorder::add_channel(std::string task_name,
                                         std::vector<std::pair<std::string, PinRef>> vars,
                                         std::size_t capacity) {
  if (vars.size() > kMaxTraceVarsPerTask) {
    throw std::invalid_argument(fmt::format("trace: task '{}' has {} traced variables; at most {}",
                                            task_name, vars.size(), kMaxTraceVarsPerTask));
  }
  if (capacity == 0 || (capacity & (capacity - 1)) != 0) {
    throw std::invalid_argument(
        fmt::format("trace: task '{}': capacity {} is not a power of two", task_name, capacity));
  }
  for (const auto& [name, ref] : vars) {
    if (ref.pin == nullptr) {
      throw std::invalid_argument(
          fmt::format("trace: task '{}': variable '{}' has no pin", task_name, name));
    }
  }
  std::lock_guard lock(drain_mutex_);
  if (header_written_) {
    throw std::logic_error("trace: add_channel after the CSV header was written");
  }
  const auto id = static_cast<std::uint32_t>(channels_.size());
  auto ch = std::make_unique<Channel>(id, csv_field(task_name), total_columns_, capacity);
  std::vector<PinRef> pins;
  pins.reserve(vars.size());
  ch->column_names.reserve(vars.size());
  for (const auto& [name, ref] : vars) {
    pins.push_back(ref);
    ch->column_names.push_back(csv_field(name));
  }
  ch->sampler.assign(pins);
  total_columns_ += vars.size();
  channels_.push_back(std::move(ch));
  return id;
}

void TraceRecorder::sample(std::uint32_t channel, TimePoint release, std::uint64_t cycle) noexcept {
  if (channel >= channels_.size()) {
    return;
  }
  Channel& ch = *channels_[channel];
  if (!ch.ring.push(ch.sampler.sample(release, cycle, channel))) {
    ch.dropped.fetch_add(1, std::memory_order_relaxed);
  }
}

std::size_t TraceRecorder::drain(std::ostream& out) {
  std::lock_guard lock(drain_mutex_);
  return drain_locked(out);
}

std::size_t TraceRecorder::drain_locked(std::ostream& out) {
  if (!header_written_) {
    row_ = "t_s,task,cycle";
    for (const auto& ch : channels_) {
      for (const auto& name : ch->column_names) {
        row_ += ',';
        row_ += name;
      }
    }
    row_ += '\n';
    out.write(row_.data(), static_cast<std::streamsize>(row_.size()));
    header_written_ = true;
  }

  // Only what is queued now: a producer that keeps pushing cannot keep this call going.
  for (auto& ch : channels_) {
    ch->remaining = ch->ring.read_available();
  }
  std::size_t rows = 0;
  for (;;) {
    Channel* next = nullptr;
    for (auto& ch : channels_) {
      if (!ch->has_head && ch->remaining > 0) {
        ch->has_head = ch->ring.pop(ch->head);
        --ch->remaining;
      }
      // Strict < keeps the lower channel first at equal release times.
      if (ch->has_head && (next == nullptr || ch->head.release < next->head.release)) {
        next = ch.get();
      }
    }
    if (next == nullptr) {
      break;
    }
    const TraceSample& s = next->head;
    row_.clear();
    append_seconds(row_, s.release);
    fmt::format_to(std::back_inserter(row_), ",{},{}", next->task_name, s.cycle);
    const std::size_t first = next->first_column;
    const std::size_t n = std::min<std::size_t>(s.n, next->sampler.size());
    for (std::size_t col = 0; col < total_columns_; ++col) {
      row_ += ',';
      if (col >= first && col < first + n) {
        fmt::format_to(std::back_inserter(row_), "{}", s.v[col - first]);
      }
    }
    row_ += '\n';
    out.write(row_.data(), static_cast<std::streamsize>(row_.size()));
    next->has_head = false;
    ++rows;
  }
  return rows;
}

void TraceRecorder::start_file_writer(const std::string& path) {
  std::lock_guard lock(writer_mutex_);
  if (writer_.joinable()) {
    throw std::logic_error("trace: file writer already running (" + file_path_ + ")");
  }
  file_.clear();
  errno = 0;
  file_.open(path, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!file_.is_open()) {
    const int err = errno;
    throw std::runtime_error(path + ": " +
                             (err != 0 ? std::generic_category().message(err) : "cannot open"));
  }
  file_path_ = path;
  write_failed_.store(false, std::memory_order_relaxed);
  writer_stop_ = false;
  writer_ = std::thread(&TraceRecorder::writer_loop, this);
}

void TraceRecorder::writer_loop() {
  bool error_logged = false;
  std::unique_lock lock(writer_mutex_);
  while (!writer_stop_) {
    lock.unlock();
    try {
      if (drain(file_) > 0) {
        file_.flush();  // so a reader following the file sees whole rows soon
      }
    } catch (const std::exception& e) {
      spdlog::error("trace: {}: {}", file_path_, e.what());
    }
    if (!file_ && !error_logged) {
      // Keep draining (so the rings do not fill) and report the failure once.
      write_failed_.store(true, std::memory_order_relaxed);
      spdlog::error("trace: {}: write failed; trace rows are being lost", file_path_);
      error_logged = true;
    }
    lock.lock();
    writer_cv_.wait_for(lock, kWriterPeriod, [this] { return writer_stop_; });
  }
}

void TraceRecorder::stop() {
  std::thread writer;
  {
    std::lock_guard lock(writer_mutex_);
    if (!writer_.joinable()) {
      return;
    }
    writer_stop_ = true;
    writer = std::move(writer_);
  }
  writer_cv_.notify_all();
  writer.join();
  drain(file_);
  file_.flush();
  const bool ok = static_cast<bool>(file_);
  file_.close();
  if (!ok || file_.fail()) {
    if (!write_failed_.exchange(true, std::memory_order_relaxed)) {
      spdlog::error("trace: {}: write failed; the trace file is incomplete", file_path_);
    }
  }
}

std::uint64_t TraceRecorder::dropped() const noexcept {
  std::uint64_t total = 0;
  for (const auto& ch : channels_) {
    total += ch->dropped.load(std::memory_order_relaxed);
  }
  return total;
}

std::uint64_t TraceRecorder::dropped(std::uint32_t channel) const noexcept {
  return channel < channels_.size() ? channels_[channel]->dropped.load(std::memory_order_relaxed)
                                    : 0;
}

}  // namespace edm::rt
