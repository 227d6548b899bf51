#pragma once
// edmplc as a long-running child of edm-bench-soak: started in the background (an
// edm::apps::Process; run_child() of bench_util.hpp serves the short edmhmi runs), its resident
// memory and open descriptors sampled from /proc, stopped with SIGINT as a user stops it.
// Non-RT. Thread-safety: start/poll/stop from one thread; sample_proc() from any.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "edm/apps/subprocess.hpp"

namespace edm::bench::soak {

struct ProcSample {
  double t_s{0};       // since the phase began
  long rss_kb{0};      // VmRSS
  int fds{0};          // entries of /proc/<pid>/fd
  bool zombie{false};  // exited, not yet reaped
};

/// One reading of /proc/<pid>; nullopt when the process is gone.
std::optional<ProcSample> sample_proc(pid_t pid);

class PlcProcess {
 public:
  /// exec args[0] (absolute path) with stdout and stderr into `log`. Empty on success.
  std::string start(const std::vector<std::string>& args, const std::filesystem::path& log);
  [[nodiscard]] pid_t pid() const { return process_.pid(); }
  /// Reaps it if it has exited; true while it runs.
  bool running() { return process_.started() && !process_.poll(); }
  /// SIGINT, then waits up to `limit` (then SIGKILL). True if it exited 0 by itself.
  bool stop(std::chrono::seconds limit);
  /// "exit code N" / "killed by signal N (name)" once reaped; empty while running.
  [[nodiscard]] std::string exit_text() const {
    return process_.ended() ? process_.describe() : std::string();
  }
  [[nodiscard]] bool exited_cleanly() const {
    return process_.ended() && process_.exit_code() == 0 && process_.term_signal() == 0;
  }

 private:
  edm::apps::Process process_;  // destroyed: SIGKILL and reaped if still running
};

}  // namespace edm::bench::soak
