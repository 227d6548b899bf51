#pragma once
// Child processes and temp files for the bench drivers: run a tool without a shell, capture its
// stdout through a pipe and its stderr into a file, with a time limit and Ctrl-C handling.
// Non-RT. Not thread-safe: one child at a time, from the main thread.

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

namespace edm::bench {

namespace fs = std::filesystem;

/// Removes the mkdtemp directory (and the stats/stderr files in it) when main returns.
class TempDir {
 public:
  TempDir() {
    std::string templ = (fs::path("/tmp") / "edm-bench-jitter.XXXXXX").string();
    if (mkdtemp(templ.data()) != nullptr) {
      path_ = templ;
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) {
      fs::remove_all(path_, ec);
    }
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct ChildResult {
  std::string error;  // non-empty: could not start, timed out or interrupted
  int exit_code{-1};  // >= 0 when the child exited normally
  int signal{0};      // the signal that ended it, if any
  std::string out;    // its stdout
};

/// Makes SIGINT and SIGTERM stop the running child (run_child() then reports "interrupted").
void install_stop_handlers();

/// Runs args[0] (an absolute path; no shell) with stdin from /dev/null, stdout captured, stderr
/// into `err_path`, optionally pinned with all its threads to `cpu` (sched_setaffinity before
/// exec). Kills it (SIGTERM, 2 s later SIGKILL) after `timeout` or on SIGINT/SIGTERM.
ChildResult run_child(const std::vector<std::string>& args, const fs::path& err_path,
                      std::optional<int> cpu, std::chrono::seconds timeout);

/// Empty when the child ran and exited 0; otherwise what went wrong, with its stderr's tail.
std::string child_failure(const std::string& tool, const ChildResult& r, const fs::path& err);

/// The whole file; empty if it cannot be read.
std::string read_file(const fs::path& path);

/// The last `n` lines of `text`, indented with "    | ", for error messages.
std::string tail_lines(const std::string& text, std::size_t n);

/// The first executable `name` in $PATH.
std::optional<std::string> find_in_path(const std::string& name);

/// Holds /dev/cpu_dma_latency at 0 us (no deep C-states) until the returned fd is closed; -1 and
/// a note on stdout when that is not allowed.
int hold_pm_qos();

}  // namespace edm::bench
