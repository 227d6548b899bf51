#include "soak_plc.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <thread>

namespace edm::bench::soak {

namespace fs = std::filesystem;

std::optional<ProcSample> sample_proc(pid_t pid) {
  const fs::path dir = fs::path("/proc") / std::to_string(pid);
  std::ifstream status(dir / "status");
  if (!status) {
    return std::nullopt;
  }
  ProcSample s;
  for (std::string line; std::getline(status, line);) {
    if (line.starts_with("VmRSS:")) {
      s.rss_kb = std::stol(line.substr(6));
    } else if (line.starts_with("State:")) {
      s.zombie = line.find('Z') != std::string::npos;
    }
  }
  std::error_code ec;
  for (fs::directory_iterator it(dir / "fd", ec), end; !ec && it != end; it.increment(ec)) {
    ++s.fds;
  }
  return s;
}

PlcProcess::~PlcProcess() {
  if (pid_ > 0 && !reaped_) {
    stop(std::chrono::seconds(10));
  }
}

std::string PlcProcess::start(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv;
  for (const auto& a : args) {
    argv.push_back(const_cast<char*>(a.c_str()));
  }
  argv.push_back(nullptr);
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (fd < 0 || null_fd < 0) {
    return fmt::format("cannot open {}: {}", log.string(), std::strerror(errno));
  }
  const pid_t pid = fork();
  if (pid == 0) {  // child: async-signal-safe calls only
    dup2(null_fd, STDIN_FILENO);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    execv(argv[0], argv.data());
    _exit(127);
  }
  ::close(fd);
  ::close(null_fd);
  if (pid < 0) {
    return fmt::format("fork: {}", std::strerror(errno));
  }
  pid_ = pid;
  reaped_ = false;
  return {};
}

void PlcProcess::record(int status) {
  reaped_ = true;
  if (WIFEXITED(status)) {
    exit_code_ = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    signal_ = WTERMSIG(status);
  }
}

bool PlcProcess::running() {
  if (pid_ <= 0 || reaped_) {
    return false;
  }
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    record(status);
    return false;
  }
  return true;
}

bool PlcProcess::stop(std::chrono::seconds limit) {
  if (!running()) {
    return exited_cleanly();
  }
  kill(pid_, SIGINT);  // edmplc stops in order: safe state, stats written
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // our child: poll its exit
  }
  if (running()) {
    kill(pid_, SIGKILL);  // still our unreaped child: the pid cannot have been reused
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    record(status);
    exit_code_ = -1;  // not a clean stop, whatever SIGKILL left
    return false;
  }
  return exited_cleanly();
}

std::string PlcProcess::exit_text() const {
  if (!reaped_) {
    return {};
  }
  if (signal_ != 0) {
    return fmt::format("killed by signal {} ({})", signal_, strsignal(signal_));
  }
  return fmt::format("exit code {}", exit_code_);
}

}  // namespace edm::bench::soak
