#pragma once
// Trace recorder: the config's `trace:` variables, sampled every cycle of the task that owns them
// and written to CSV (`--trace-out FILE.csv`).
//
// Each task with traced variables gets one channel: a lock-free SPSC ring whose producer is that
// task's RT thread (sample()) and whose consumer is the non-RT drain (drain() or the file writer
// thread). A full ring drops the sample and counts it; the task never waits.
//
// CSV (deterministic, diffable):
//   header  t_s,task,cycle,<var>,<var>,...   every variable of every channel, in channel order
//   row     one sample of one task: release time in seconds printed exactly from the integer ns
//           (0.001000000), task name, cycle number, that channel's values in its columns (fmt
//           "{}", shortest round-trip; bools as 0/1) and empty fields in the other channels'.
// Rows of one channel come in push order; rows of different channels are merged by
// (release, channel) among the samples queued when drain() runs, so a scheduler that drains
// between cycles (virtual clock) gets a file in time order.
//
// Thread-safety / RT-safety:
//  - add_channel(): non-RT, before sampling starts; never concurrently with anything else.
//  - sample(): RT-safe (no allocation, no lock, noexcept); for a given channel, from one thread
//    at a time (the owning task's thread).
//  - drain(), start_file_writer(), stop(): non-RT; serialised by an internal mutex the RT side
//    never takes.
//  - dropped(): RT-safe, any thread.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "edm/runtime/pin.hpp"
#include "edm/runtime/pin_sampler.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

class TraceRecorder {
 public:
  TraceRecorder();
  /// Stops the file writer if it runs.
  ~TraceRecorder();
  TraceRecorder(const TraceRecorder&) = delete;
  TraceRecorder& operator=(const TraceRecorder&) = delete;

  /// Non-RT, before sampling starts: one channel per task that has traced variables.
  /// vars are (full variable name, pin); capacity is the ring size in samples.
  /// Returns the channel id (0, 1, ... in call order). Throws std::invalid_argument if there are
  /// more than kMaxTraceVarsPerTask vars, a pin is null, or capacity is not a power of two;
  /// std::logic_error once the CSV header has been written (the columns are fixed then).
  std::uint32_t add_channel(std::string task_name, std::vector<std::pair<std::string, PinRef>> vars,
                            std::size_t capacity);

  /// Samples the channel's variables (PinSampler) and pushes the sample; a full ring
  /// drops it and counts the drop. An unknown channel is ignored.
  /// RT-safe: no allocation, no lock, never blocks. One producer thread per channel.
  void sample(std::uint32_t channel, TimePoint release, std::uint64_t cycle) noexcept;

  /// Non-RT: writes the CSV header on the first call, then every sample queued now, as rows.
  /// Returns the number of rows written.
  std::size_t drain(std::ostream& out);

  /// Non-RT: starts a thread that drains into the file at path every few ms until stop().
  /// Throws std::runtime_error ("<path>: <strerror>") if the file cannot be opened,
  /// std::logic_error if a writer already runs.
  void start_file_writer(const std::string& path);

  /// Non-RT: stops the file writer, drains what is left, closes the file. No-op without a
  /// writer. Does not throw on a failed write (the shutdown path must go on): it logs an error
  /// and write_failed() turns true.
  void stop();

  /// True once writing the trace file has failed (e.g. disk full). Any thread.
  [[nodiscard]] bool write_failed() const noexcept {
    return write_failed_.load(std::memory_order_relaxed);
  }

  /// Samples dropped on full rings: total over channels, or for one channel (0 if unknown).
  /// RT-safe, any thread.
  [[nodiscard]] std::uint64_t dropped() const noexcept;
  [[nodiscard]] std::uint64_t dropped(std::uint32_t channel) const noexcept;

  [[nodiscard]] std::size_t channel_count() const noexcept { return channels_.size(); }

 private:
  struct Channel;  // defined in trace.cpp; holds the Boost.Lockfree ring

  std::size_t drain_locked(std::ostream& out);
  void writer_loop();

  std::vector<std::unique_ptr<Channel>> channels_;
  std::size_t total_columns_{0};  // variables over all channels

  std::mutex drain_mutex_;  // one consumer at a time; the RT producers never take it
  bool header_written_{false};
  std::string row_;  // reused row buffer, so steady-state draining does not allocate

  std::mutex writer_mutex_;  // guards the fields below
  std::condition_variable writer_cv_;
  bool writer_stop_{false};
  std::thread writer_;
  std::ofstream file_;
  std::string file_path_;
  std::atomic<bool> write_failed_{false};
};

}  // namespace edm::rt
