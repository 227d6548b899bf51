#pragma once
// The job log (issue 33, "a job log"): every job that ended — finished or aborted (an operator
// stop, a fault, an E-stop) — with its figures, its alarms, the electrode before and after, and
// when. Kept beside the retain file as CSV (`<retain file>.jobs.csv`: a spreadsheet reads it),
// rewritten whole (temp file, fsync, rename) at each job's end, capped to the newest `cap`
// entries. Without a retain file it is kept in memory only. Server thread only; never RT.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace edm::bridge {

struct JobLogEntry {
  std::uint64_t n{0};   // the job's number in this log, from 1
  std::string start;    // UTC, "2026-12-03T12:34:56.789Z"
  std::string end;      // UTC
  std::string outcome;  // finished, aborted
  std::string slot;     // main, mdi
  bool dry_run{false};
  std::string program;  // the program's CRC-32, "0x1a2b3c4d"
  std::uint64_t blocks_done{0}, blocks{0};
  int line{0};           // the G-code line it ended on
  double time_s{0.0};    // machining time (cnc.job.job_time_s)
  double depth_mm{0.0};  // deepest depth reached (cnc.job.job_depth_mm)
  double wear_mm{0.0};   // estimated electrode wear (cnc.job.job_wear_mm)
  double electrode_start_mm{0.0}, electrode_end_mm{0.0};  // the estimate (0: unknown)
  int cause{0};           // the machine's fault cause when it ended aborted in a safe state
  std::string alarms;     // "110 block_fault cnc.job.finish: no spark …; …"
  std::string electrode;  // the electrode table's id of the one used ("" when none named)
  std::int64_t holes{0};  // drilling blocks begun (cnc.job.job_holes)
};

class JobLog {
 public:
  /// `path` empty: in memory only. Loads the file when there is one; a file that cannot be read
  /// is set aside as `<path>.bad` and the log starts empty (load_error() says why).
  JobLog(std::string path, std::size_t cap);

  /// Appends (numbering it) and writes the file; false when the write failed (the entry is kept
  /// in memory).
  bool add(JobLogEntry e);
  [[nodiscard]] const std::deque<JobLogEntry>& entries() const noexcept { return entries_; }
  [[nodiscard]] std::string csv() const;
  [[nodiscard]] bool retained() const noexcept { return !path_.empty(); }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] const std::string& load_error() const noexcept { return load_error_; }

  static const std::vector<std::string>& columns();

 private:
  void load();

  std::string path_;
  std::size_t cap_;
  std::deque<JobLogEntry> entries_;
  std::uint64_t next_n_{1};
  std::string load_error_;
};

}  // namespace edm::bridge
