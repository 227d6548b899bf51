#include "subprocess.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace edm::bench {

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int /*sig*/) { g_stop = 1; }

/// Makes `fd` become `target` in the child. dup2(fd, fd) would keep FD_CLOEXEC set.
void move_fd(int fd, int target) {
  if (fd == target) {
    fcntl(target, F_SETFD, 0);
  } else {
    dup2(fd, target);
  }
}

}  // namespace

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;  // no SA_RESTART: poll() returns EINTR and we stop the child
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string tail_lines(const std::string& text, std::size_t n) {
  std::size_t pos = text.size();
  while (pos > 0 && text[pos - 1] == '\n') {
    --pos;
  }
  std::size_t start = pos;
  for (std::size_t lines = 0; start > 0 && lines < n; --start) {
    if (text[start - 1] == '\n' && ++lines == n) {
      break;
    }
  }
  std::string out;
  std::istringstream in(text.substr(start, pos - start));
  for (std::string line; std::getline(in, line);) {
    out += "    | " + line + "\n";
  }
  return out;
}

std::optional<std::string> find_in_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (access(candidate.c_str(), X_OK) == 0) {
      return candidate.string();
    }
  }
  return std::nullopt;
}

ChildResult run_child(const std::vector<std::string>& args, const fs::path& err_path,
                      std::optional<int> cpu, std::chrono::seconds timeout) {
  ChildResult result;
  std::vector<char*> argv;
  for (const auto& a : args) {
    argv.push_back(const_cast<char*>(a.c_str()));
  }
  argv.push_back(nullptr);
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (cpu) {
    CPU_SET(static_cast<std::size_t>(*cpu), &cpus);
  }
  int out_pipe[2] = {-1, -1};
  int exec_pipe[2] = {-1, -1};  // carries the child's errno if exec fails; EOF on success
  const int err_fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  const int null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (err_fd < 0 || null_fd < 0 || pipe2(out_pipe, O_CLOEXEC) != 0 ||
      pipe2(exec_pipe, O_CLOEXEC) != 0) {
    result.error = fmt::format("cannot set up pipes/files: {}", std::strerror(errno));
    for (const int fd : {err_fd, null_fd, out_pipe[0], out_pipe[1], exec_pipe[0], exec_pipe[1]}) {
      if (fd >= 0) {
        close(fd);
      }
    }
    return result;
  }
  const pid_t pid = fork();
  if (pid == 0) {  // child: async-signal-safe calls only
    move_fd(null_fd, STDIN_FILENO);
    move_fd(out_pipe[1], STDOUT_FILENO);
    move_fd(err_fd, STDERR_FILENO);
    if (!cpu || sched_setaffinity(0, sizeof cpus, &cpus) == 0) {
      execv(argv[0], argv.data());
    }
    const int err = errno;
    [[maybe_unused]] const ssize_t n = write(exec_pipe[1], &err, sizeof err);
    _exit(127);
  }
  close(out_pipe[1]);
  close(exec_pipe[1]);
  close(err_fd);
  close(null_fd);
  if (pid < 0) {
    result.error = fmt::format("fork: {}", std::strerror(errno));
    close(out_pipe[0]);
    close(exec_pipe[0]);
    return result;
  }
  int child_errno = 0;
  ssize_t got = 0;
  do {
    got = read(exec_pipe[0], &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR);
  close(exec_pipe[0]);
  if (got == static_cast<ssize_t>(sizeof child_errno)) {
    result.error = fmt::format("cannot run {}: {}", args[0], std::strerror(child_errno));
  }

  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool eof = !result.error.empty();
  bool killed = false;
  bool reaped = false;
  int status = 0;
  char buf[4096];
  for (;;) {
    if (!killed && (g_stop != 0 || std::chrono::steady_clock::now() > deadline)) {
      if (result.error.empty()) {
        result.error =
            g_stop != 0 ? "interrupted" : fmt::format("no exit after {} s", timeout.count());
      }
      kill(pid, SIGTERM);
      for (int i = 0; i < 200 && !reaped; ++i) {
        reaped = waitpid(pid, &status, WNOHANG) == pid;
        usleep(reaped ? 0 : 10'000);
      }
      if (!reaped) {
        kill(pid, SIGKILL);  // still our unreaped child, so the pid cannot have been reused
      }
      killed = true;
      break;
    }
    if (eof) {
      const pid_t done = waitpid(pid, &status, WNOHANG);
      if (done == pid) {
        break;
      }
      usleep(10'000);
      continue;
    }
    pollfd pfd{out_pipe[0], POLLIN, 0};
    if (poll(&pfd, 1, 100) <= 0) {
      continue;  // timeout or EINTR: check the deadline and the stop flag
    }
    const ssize_t n = read(out_pipe[0], buf, sizeof buf);
    if (n > 0) {
      result.out.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      eof = true;
    }
  }
  close(out_pipe[0]);
  if (killed && !reaped) {
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

std::string child_failure(const std::string& tool, const ChildResult& r, const fs::path& err) {
  std::string what;
  if (!r.error.empty()) {
    what = r.error;
  } else if (r.signal != 0) {
    what = fmt::format("killed by signal {} ({})", r.signal, strsignal(r.signal));
  } else if (r.exit_code != 0) {
    what = fmt::format("exit code {}", r.exit_code);
  } else {
    return {};
  }
  return fmt::format("{} failed: {}\n{}{}", tool, what, tail_lines(read_file(err), 15),
                     tail_lines(r.out, 5));
}

/// Same C-state limit for both tools: cyclictest sets it by itself, edmplc does not.
int hold_pm_qos() {
  const int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  const std::int32_t zero = 0;
  if (fd < 0 || write(fd, &zero, sizeof zero) != static_cast<ssize_t>(sizeof zero)) {
    fmt::print(
        "note: cannot hold /dev/cpu_dma_latency at 0 us ({}): edmplc may see deeper "
        "C-states than cyclictest, which sets it itself\n",
        std::strerror(errno));
    if (fd >= 0) {
      close(fd);
    }
    return -1;
  }
  return fd;
}

}  // namespace edm::bench
