#pragma once
// The one way tests and bench drivers run a child process (issue 18): fork + exec without a shell,
// each standard stream inherited, /dev/null, a pipe or a file; the child leads its own process
// group; waits block in poll() on the child's pidfd and its output pipe (no sleeps); a timeout or a
// stop ends the whole group (the signal asked for, then SIGKILL).
// Non-RT. A Process is not thread-safe: use it from one thread (pid() may be read from any).

#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace edm::apps {

/// Where one of the child's standard streams goes.
enum class Stream : std::uint8_t {
  kInherit,  // the parent's
  kNull,     // /dev/null
  kPipe,     // stdin: write_input(); stdout: output(), read_until(), wait()
  kFile,     // SpawnOptions::out_file / err_file, truncated (stdin: not allowed)
  kStdout,   // stderr only: wherever stdout goes
};

struct SpawnOptions {
  Stream in{Stream::kNull};
  Stream out{Stream::kPipe};
  Stream err{Stream::kStdout};
  std::filesystem::path out_file;
  std::filesystem::path err_file;
  std::vector<std::string> unset_env;  // removed from the inherited environment
  std::vector<std::pair<std::string, std::string>> set_env;  // then set
  std::optional<int> cpu;  // pin the child (and every thread it starts) to this CPU before exec
};

/// A child process. Destroying a running one sends SIGKILL to its group and reaps it.
class Process {
 public:
  using Ms = std::chrono::milliseconds;

  Process() = default;
  /// Starts argv[0] (a path, or a bare name looked up in $PATH). If it cannot start (no such
  /// file, not executable, no pipe), started() is false and error() says why.
  explicit Process(const std::vector<std::string>& argv, const SpawnOptions& options = {});
  /// Forks and runs `body` in the child, which then _exits 0 (3 if body throws): for tests that
  /// need their own code in a second process, e.g. a writer to kill mid-write.
  static Process fork_call(const std::function<void()>& body, const SpawnOptions& options = {});
  ~Process();
  Process(Process&& other) noexcept;
  Process& operator=(Process&& other) noexcept;
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  [[nodiscard]] bool started() const { return pid_ > 0; }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] pid_t pid() const { return pid_; }
  /// What the stdout pipe has delivered so far.
  [[nodiscard]] const std::string& output() const { return output_; }

  /// Reads the stdout pipe until the output contains `text`, the pipe closes or `timeout` passes.
  bool read_until(std::string_view text, Ms timeout);
  /// Waits up to `timeout` for more output; false when none came (closed pipe or timeout).
  bool read_some(Ms timeout);
  /// Writes to the stdin pipe; false if it is closed.
  bool write_input(std::string_view text);
  void close_input();

  /// Sends `sig` to the child itself while it has not been reaped.
  void signal(int sig) const;
  /// Reaps the child if it has ended: its status (the exit code, or 128 + the signal).
  std::optional<int> poll();
  /// Reads the output while waiting for the end; the status, or nullopt when `timeout` passed (or
  /// a stop handler of install_stop_handlers() ran) first.
  std::optional<int> wait(Ms timeout);
  /// Waits without a deadline.
  int wait();
  /// `sig` to the group, up to `grace` for the end, then SIGKILL to the group. The status.
  int stop(int sig = SIGTERM, Ms grace = Ms(2000));
  /// SIGKILL to the group, reaped (nothing once it has ended).
  void kill();

  /// After the end: the exit code (-1 if killed) and the signal that ended it (0 if none).
  [[nodiscard]] int exit_code() const { return exit_code_; }
  [[nodiscard]] int term_signal() const { return signal_; }
  [[nodiscard]] bool ended() const { return reaped_; }
  /// "exit code N", "killed by signal N (name)" or "running".
  [[nodiscard]] std::string describe() const;

 private:
  void start(const std::vector<std::string>* argv, const std::function<void()>* body,
             const SpawnOptions& options);
  void record(int status);
  bool pump(int timeout_ms);  // one poll() on the pidfd and the pipe; false on timeout
  void drain();               // whatever the pipe still holds, without blocking
  void close_fds();

  pid_t pid_{-1};
  int pidfd_{-1};
  int out_fd_{-1};
  int in_fd_{-1};
  bool reaped_{false};
  int exit_code_{-1};
  int signal_{0};
  std::string error_;
  std::string output_;
};

/// What run() saw.
struct RunResult {
  std::string error;  // non-empty: could not start, timed out or interrupted
  int exit_code{-1};  // >= 0 when it exited by itself
  int signal{0};      // the signal that ended it, if any
  std::string out;    // its stdout (when SpawnOptions::out is kPipe)
  /// Empty when it ran and exited 0; otherwise "`tool` failed: what".
  [[nodiscard]] std::string failure(std::string_view tool) const;
};

/// Runs argv to its end. After `timeout` (or a stop handler's signal) the group gets SIGTERM and,
/// 2 s later, SIGKILL.
RunResult run(const std::vector<std::string>& argv, const SpawnOptions& options,
              std::chrono::milliseconds timeout);

/// Makes SIGINT and SIGTERM interrupt every wait of this process (wait() then returns nullopt and
/// run() reports "interrupted"), for drivers that must stop their child on Ctrl-C.
void install_stop_handlers();
[[nodiscard]] bool stop_requested();

/// The first executable `name` in $PATH (a name with a '/' is returned as it is).
std::optional<std::string> find_in_path(const std::string& name);

}  // namespace edm::apps
