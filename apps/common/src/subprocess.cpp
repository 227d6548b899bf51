#include "edm/apps/subprocess.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>

extern char** environ;

namespace edm::apps {

namespace {

using Clock = std::chrono::steady_clock;

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

void close_fd(int& fd) {
  if (fd >= 0) {
    ::close(fd);
  }
  fd = -1;
}

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(left, 0, 60'000));
}

/// The environment for the child, built before fork (the child only calls async-signal-safe
/// functions). Empty when the parent's is inherited unchanged.
std::vector<std::string> child_environment(const SpawnOptions& o) {
  std::vector<std::string> env;
  if (o.unset_env.empty() && o.set_env.empty()) {
    return env;
  }
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view v(*e);
    const auto removed = [&](const std::string& name) {
      return v.starts_with(name) && v.size() > name.size() && v[name.size()] == '=';
    };
    const bool set_again = std::any_of(o.set_env.begin(), o.set_env.end(),
                                       [&](const auto& kv) { return removed(kv.first); });
    if (!set_again && std::none_of(o.unset_env.begin(), o.unset_env.end(), removed)) {
      env.emplace_back(v);
    }
  }
  for (const auto& [k, v] : o.set_env) {
    env.push_back(k + "=" + v);
  }
  return env;
}

}  // namespace

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;  // no SA_RESTART: poll() returns EINTR and the wait ends
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool stop_requested() { return g_stop != 0; }

std::optional<std::string> find_in_path(const std::string& name) {
  if (name.find('/') != std::string::npos) {
    return name;
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / name;
    if (access(candidate.c_str(), X_OK) == 0) {
      return candidate.string();
    }
  }
  return std::nullopt;
}

Process::Process(const std::vector<std::string>& argv, const SpawnOptions& options) {
  start(&argv, nullptr, options);
}

Process Process::fork_call(const std::function<void()>& body, const SpawnOptions& options) {
  Process p;
  p.start(nullptr, &body, options);
  return p;
}

Process::~Process() {
  kill();
  close_fds();
}

Process::Process(Process&& other) noexcept { *this = std::move(other); }

Process& Process::operator=(Process&& other) noexcept {
  if (this != &other) {
    kill();
    close_fds();
    pid_ = std::exchange(other.pid_, -1);
    pidfd_ = std::exchange(other.pidfd_, -1);
    out_fd_ = std::exchange(other.out_fd_, -1);
    in_fd_ = std::exchange(other.in_fd_, -1);
    reaped_ = other.reaped_;
    exit_code_ = other.exit_code_;
    signal_ = other.signal_;
    error_ = std::move(other.error_);
    output_ = std::move(other.output_);
  }
  return *this;
}

void Process::close_fds() {
  close_fd(pidfd_);
  close_fd(out_fd_);
  close_fd(in_fd_);
}

void Process::start(const std::vector<std::string>* argv, const std::function<void()>* body,
                    const SpawnOptions& o) {
  std::string path;
  if (argv != nullptr) {
    if (argv->empty()) {
      error_ = "no program to run";
      return;
    }
    const auto found = find_in_path(argv->front());
    if (!found) {
      error_ = "cannot run " + argv->front() + ": not found in $PATH";
      return;
    }
    path = *found;
  }
  std::vector<char*> args;
  if (argv != nullptr) {
    for (const auto& a : *argv) {
      args.push_back(const_cast<char*>(a.c_str()));
    }
    args.push_back(nullptr);
  }
  std::vector<std::string> env_text = child_environment(o);
  std::vector<char*> envp;
  for (auto& e : env_text) {
    envp.push_back(e.data());
  }
  envp.push_back(nullptr);
  char** const child_env = env_text.empty() ? environ : envp.data();
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (o.cpu) {
    CPU_SET(static_cast<std::size_t>(*o.cpu), &cpus);
  }

  // Every descriptor is opened O_CLOEXEC here and moved onto 0/1/2 in the child.
  int in_pipe[2] = {-1, -1}, out_pipe[2] = {-1, -1}, exec_pipe[2] = {-1, -1};
  int in_fd = -1, out_fd = -1, err_fd = -1;
  const auto open_file = [](const std::filesystem::path& p) {
    return ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  };
  const auto open_null = [](int flags) { return ::open("/dev/null", flags | O_CLOEXEC); };
  bool ok = pipe2(exec_pipe, O_CLOEXEC) == 0;
  if (ok && o.in == Stream::kPipe) {
    ok = pipe2(in_pipe, O_CLOEXEC) == 0;
    in_fd = in_pipe[0];
  } else if (ok && o.in == Stream::kNull) {
    ok = (in_fd = open_null(O_RDONLY)) >= 0;
  }
  if (ok && o.out == Stream::kPipe) {
    ok = pipe2(out_pipe, O_CLOEXEC) == 0;
    out_fd = out_pipe[1];
  } else if (ok && o.out == Stream::kNull) {
    ok = (out_fd = open_null(O_WRONLY)) >= 0;
  } else if (ok && o.out == Stream::kFile) {
    ok = (out_fd = open_file(o.out_file)) >= 0;
  }
  if (ok && o.err == Stream::kStdout) {
    err_fd = o.out == Stream::kInherit ? -2 : out_fd;  // -2: dup the parent's stdout
  } else if (ok && o.err == Stream::kNull) {
    ok = (err_fd = open_null(O_WRONLY)) >= 0;
  } else if (ok && o.err == Stream::kFile) {
    ok = (err_fd = open_file(o.err_file)) >= 0;
  }
  const auto close_all = [&] {
    for (int* fd :
         {&in_pipe[0], &in_pipe[1], &out_pipe[0], &out_pipe[1], &exec_pipe[0], &exec_pipe[1]}) {
      close_fd(*fd);
    }
    if (o.in == Stream::kNull) close_fd(in_fd);
    if (o.out == Stream::kNull || o.out == Stream::kFile) close_fd(out_fd);
    if (o.err == Stream::kNull || o.err == Stream::kFile) close_fd(err_fd);
  };
  if (!ok) {
    error_ = std::string("cannot set up the child's streams: ") + std::strerror(errno);
    close_all();
    return;
  }

  const pid_t pid = ::fork();
  if (pid == 0) {  // the child: async-signal-safe calls only, until exec (or body)
    setpgid(0, 0);
    if (in_fd >= 0) move_fd(in_fd, STDIN_FILENO);
    if (out_fd >= 0) move_fd(out_fd, STDOUT_FILENO);
    if (err_fd == -2) {
      dup2(STDOUT_FILENO, STDERR_FILENO);
    } else if (err_fd >= 0) {
      move_fd(err_fd, STDERR_FILENO);
    }
    if (!o.cpu || sched_setaffinity(0, sizeof cpus, &cpus) == 0) {
      if (body != nullptr) {
        close_fd(exec_pipe[1]);  // "started" for the parent
        try {
          (*body)();
        } catch (...) {
          _exit(3);
        }
        _exit(0);
      }
      execve(path.c_str(), args.data(), child_env);
    }
    const int err = errno;
    [[maybe_unused]] const ssize_t n = write(exec_pipe[1], &err, sizeof err);
    _exit(127);
  }
  const int fork_errno = errno;
  const int parent_in = in_pipe[1], parent_out = out_pipe[0];
  in_pipe[1] = out_pipe[0] = -1;
  const int exec_read = std::exchange(exec_pipe[0], -1);
  close_all();
  if (pid < 0) {
    error_ = std::string("fork: ") + std::strerror(fork_errno);
    ::close(exec_read);
    if (parent_in >= 0) ::close(parent_in);
    if (parent_out >= 0) ::close(parent_out);
    return;
  }
  setpgid(pid, pid);  // as the child does: whichever runs first
  pid_ = pid;
  in_fd_ = parent_in;
  out_fd_ = parent_out;
  if (out_fd_ >= 0) {
    fcntl(out_fd_, F_SETFL, fcntl(out_fd_, F_GETFL) | O_NONBLOCK);
  }
  pidfd_ = static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));  // -1: fall back to polling
  int child_errno = 0;
  ssize_t got = 0;
  do {
    got = ::read(exec_read, &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR);
  ::close(exec_read);
  if (got == static_cast<ssize_t>(sizeof child_errno)) {
    error_ = "cannot run " + path + ": " + std::strerror(child_errno);
    wait();
    pid_ = -1;
  }
}

void Process::record(int status) {
  reaped_ = true;
  if (WIFEXITED(status)) {
    exit_code_ = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    signal_ = WTERMSIG(status);
  }
  close_fd(pidfd_);
}

std::optional<int> Process::poll() {
  if (pid_ > 0 && !reaped_) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      record(status);
    }
  }
  if (!reaped_) {
    return std::nullopt;
  }
  return signal_ != 0 ? 128 + signal_ : exit_code_;
}

void Process::drain() {
  char buf[4096];
  while (out_fd_ >= 0) {
    const ssize_t n = ::read(out_fd_, buf, sizeof buf);
    if (n > 0) {
      output_.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || (errno != EINTR)) {
      if (n == 0) close_fd(out_fd_);  // EOF; EAGAIN: nothing more for now
      return;
    }
  }
}

bool Process::pump(int timeout_ms) {
  pollfd fds[2];
  nfds_t n = 0;
  if (out_fd_ >= 0) fds[n++] = {out_fd_, POLLIN, 0};
  if (pidfd_ >= 0 && !reaped_) fds[n++] = {pidfd_, POLLIN, 0};
  // Without a pidfd (kernel < 5.3) the end is noticed at most 20 ms late.
  const bool fallback = pidfd_ < 0 && !reaped_;
  const int r = ::poll(fds, n, fallback ? std::min(timeout_ms, 20) : timeout_ms);
  if (r < 0) {
    return false;  // EINTR: the caller checks its deadline and stop_requested()
  }
  drain();
  poll();
  return r > 0;
}

bool Process::read_until(std::string_view text, Ms timeout) {
  const auto deadline = Clock::now() + timeout;
  drain();
  while (output_.find(text) == std::string::npos) {
    if (out_fd_ < 0 || Clock::now() >= deadline) {
      return false;
    }
    pump(remaining_ms(deadline));
  }
  return true;
}

bool Process::read_some(Ms timeout) {
  const auto deadline = Clock::now() + timeout;
  const std::size_t before = output_.size();
  drain();
  while (output_.size() == before && out_fd_ >= 0 && Clock::now() < deadline) {
    pump(remaining_ms(deadline));
  }
  return output_.size() > before;
}

bool Process::write_input(std::string_view text) {
  while (!text.empty() && in_fd_ >= 0) {
    const ssize_t n = ::write(in_fd_, text.data(), text.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return text.empty();
}

void Process::close_input() { close_fd(in_fd_); }

void Process::signal(int sig) const {
  if (pid_ > 0 && !reaped_) {
    ::kill(pid_, sig);
  }
}

std::optional<int> Process::wait(Ms timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (const auto status = poll()) {
      drain();
      return status;
    }
    if (pid_ <= 0 || Clock::now() >= deadline || stop_requested()) {
      return std::nullopt;
    }
    pump(remaining_ms(deadline));
  }
}

int Process::wait() {
  while (pid_ > 0) {
    if (const auto status = wait(Ms(60'000))) return *status;
    if (stop_requested()) return stop();
  }
  return -1;
}

int Process::stop(int sig, Ms grace) {
  if (pid_ <= 0) return -1;
  if (!poll()) {
    ::kill(-pid_, sig);  // still our unreaped child: its group id cannot have been reused
    const auto deadline = Clock::now() + grace;
    while (!poll() && Clock::now() < deadline) {
      pump(remaining_ms(deadline));
    }
    kill();
  }
  drain();
  return *poll();
}

void Process::kill() {
  if (pid_ <= 0 || reaped_) return;
  ::kill(-pid_, SIGKILL);
  ::kill(pid_, SIGKILL);  // in case it left its group
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  record(status);
}

std::string Process::describe() const {
  if (!reaped_) return "running";
  if (signal_ != 0) {
    return "killed by signal " + std::to_string(signal_) + " (" + strsignal(signal_) + ")";
  }
  return "exit code " + std::to_string(exit_code_);
}

std::string RunResult::failure(std::string_view tool) const {
  std::string what;
  if (!error.empty()) {
    what = error;
  } else if (signal != 0) {
    what = "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
  } else if (exit_code != 0) {
    what = "exit code " + std::to_string(exit_code);
  } else {
    return {};
  }
  return std::string(tool) + " failed: " + what;
}

RunResult run(const std::vector<std::string>& argv, const SpawnOptions& options,
              std::chrono::milliseconds timeout) {
  RunResult r;
  Process p(argv, options);
  if (!p.started()) {
    r.error = p.error();
    return r;
  }
  if (!p.wait(timeout)) {
    r.error = stop_requested() ? "interrupted"
                               : "no exit after " + std::to_string(timeout.count() / 1000) + " s";
    p.stop(SIGTERM, std::chrono::seconds(2));
  }
  r.exit_code = p.exit_code();
  r.signal = p.term_signal();
  r.out = p.output();
  return r;
}

}  // namespace edm::apps
