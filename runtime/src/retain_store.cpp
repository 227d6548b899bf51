// RetainStore: the non-RT thread that polls retained variables and writes the retain file on
// change (rate-limited) and at stop. The file format and the atomic write are in retain.cpp.

#include <fmt/format.h>
#include <pthread.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <map>
#include <stdexcept>

#include "edm/runtime/retain.hpp"

namespace edm::rt {
namespace {

TimePoint steady_now() {
  return std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now().time_since_epoch());
}

}  // namespace

RetainStore::RetainStore(std::string path, Duration min_interval, std::vector<Variable> vars)
    : path_(std::move(path)), min_interval_(min_interval), vars_(std::move(vars)) {
  if (min_interval_ < Duration::zero()) {
    throw std::invalid_argument("retain: min_interval must not be negative");
  }
  std::map<std::string_view, std::size_t> seen;
  current_.reserve(vars_.size());
  for (std::size_t k = 0; k < vars_.size(); ++k) {
    const Variable& v = vars_[k];
    if (!is_valid_retain_name(v.name)) {
      throw std::invalid_argument(
          fmt::format("retain: variable {} has an invalid name (printable ASCII, no spaces)", k));
    }
    if (!seen.emplace(v.name, k).second) {
      throw std::invalid_argument(fmt::format("retain: duplicate variable '{}'", v.name));
    }
    if (!v.read) {
      throw std::invalid_argument(
          fmt::format("retain: variable '{}' has no read function", v.name));
    }
    current_.push_back(RetainValue{v.type, false, 0, 0.0});
  }
  type_mismatch_logged_.assign(vars_.size(), false);
}

RetainStore::~RetainStore() { stop(); }

void RetainStore::read_all_locked() {
  for (std::size_t k = 0; k < vars_.size(); ++k) {
    const RetainValue v = vars_[k].read();
    if (v.type == vars_[k].type) {
      current_[k] = v;
    } else if (!type_mismatch_logged_[k]) {
      type_mismatch_logged_[k] = true;
      spdlog::error("retain: '{}' is {} but read() returned {}; keeping its last value",
                    vars_[k].name, to_string(vars_[k].type), to_string(v.type));
    }
  }
}

bool RetainStore::write_locked() noexcept {
  try {
    RetainMap map;
    for (std::size_t k = 0; k < vars_.size(); ++k) {
      map.emplace(vars_[k].name, current_[k]);
    }
    write_retain_file_atomic(path_, map);
    written_ = current_;
    writes_.fetch_add(1, std::memory_order_relaxed);
    failing_.store(false, std::memory_order_release);
    if (write_listener_) write_listener_(true);
    if (failure_streak_ > 0) {
      spdlog::info("retain: writing '{}' works again after {} failed attempts", path_,
                   failure_streak_);
      failure_streak_ = 0;
    }
    return true;
  } catch (const std::exception& e) {
    write_failures_.fetch_add(1, std::memory_order_relaxed);
    failing_.store(true, std::memory_order_release);
    ++failure_streak_;
    // First failure, then every 100th: a full disk must be visible but not flood the log.
    if (failure_streak_ % 100 == 1) {
      spdlog::error("retain: write failed ({} in a row, retrying on change): {}", failure_streak_,
                    e.what());
    }
    try {
      if (write_listener_) write_listener_(false);
    } catch (...) {  // the listener raises an alarm (lock-free); nothing of it may escape
    }
    return false;
  }
}

bool RetainStore::poll(TimePoint now) noexcept {
  try {
    const std::lock_guard lock(mutex_);
    read_all_locked();
    if (written_ && *written_ == current_) {
      return false;
    }
    bool urgent = false;
    for (std::size_t k = 0; k < vars_.size() && !urgent; ++k) {
      urgent = vars_[k].urgent && (!written_ || !((*written_)[k] == current_[k]));
    }
    // A `now` before the last attempt means a new time line (e.g. virtual, then real): no wait.
    if (!urgent && last_attempt_ && now >= *last_attempt_ && now - *last_attempt_ < min_interval_) {
      return false;
    }
    last_attempt_ = now;
    return write_locked();
  } catch (const std::exception& e) {
    write_failures_.fetch_add(1, std::memory_order_relaxed);
    spdlog::error("retain: poll of '{}' failed: {}", path_, e.what());
    return false;
  }
}

bool RetainStore::flush() noexcept { return sync() == SyncResult::kWritten; }

RetainStore::SyncResult RetainStore::sync() noexcept {
  try {
    const std::lock_guard lock(mutex_);
    read_all_locked();
    if (written_ && *written_ == current_) {
      return SyncResult::kUnchanged;
    }
    return write_locked() ? SyncResult::kWritten : SyncResult::kFailed;
  } catch (const std::exception& e) {
    write_failures_.fetch_add(1, std::memory_order_relaxed);
    failing_.store(true, std::memory_order_release);
    spdlog::error("retain: flush of '{}' failed: {}", path_, e.what());
    return SyncResult::kFailed;
  }
}

bool RetainStore::retains(std::string_view name) const noexcept {
  for (const Variable& v : vars_) {
    if (v.name == name) return true;
  }
  return false;
}

void RetainStore::start(Duration poll_period) {
  if (thread_.joinable()) {
    throw std::logic_error("retain: store already started");
  }
  if (poll_period <= Duration::zero()) {
    throw std::invalid_argument("retain: poll_period must be positive");
  }
  if (const std::size_t n = remove_stale_retain_temps(path_); n > 0) {
    spdlog::info("retain: removed {} temp file(s) left by an interrupted write of '{}'", n, path_);
  }
  {
    const std::lock_guard lock(thread_mutex_);
    stop_requested_ = false;
  }
  {
    // The thread polls on the steady clock; earlier polls may have used another time line.
    const std::lock_guard lock(mutex_);
    last_attempt_.reset();
  }
  stopped_ = false;
  thread_ = std::thread([this, poll_period] { run(poll_period); });
  // Shows up in top/ps; failure to name the thread is harmless.
  ::pthread_setname_np(thread_.native_handle(), "edm-retain");
}

void RetainStore::run(Duration poll_period) noexcept {
  std::unique_lock lock(thread_mutex_);
  while (!stop_requested_) {
    lock.unlock();
    poll(steady_now());
    lock.lock();
    wake_.wait_for(lock, poll_period, [this] { return stop_requested_; });
  }
}

void RetainStore::stop() noexcept {
  if (stopped_) {
    return;
  }
  {
    const std::lock_guard lock(thread_mutex_);
    stop_requested_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  }
  flush();
  stopped_ = true;
}

}  // namespace edm::rt
