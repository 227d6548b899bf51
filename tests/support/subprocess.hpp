#pragma once
// Runs a child process for tests: argv, stderr captured through a pipe, signals, exit status.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

namespace edm::test {

class Child {
 public:
  explicit Child(const std::vector<std::string>& argv) {
    int fds[2];
    if (pipe(fds) != 0) {
      return;
    }
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDERR_FILENO);
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      std::vector<char*> args;
      for (const auto& a : argv) {
        args.push_back(const_cast<char*>(a.c_str()));
      }
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
    close(fds[1]);
    out_fd_ = fds[0];
  }
  ~Child() {
    if (pid_ > 0 && status_ < 0) {
      kill(pid_, SIGKILL);
      wait();
    }
    if (out_fd_ >= 0) {
      close(out_fd_);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Reads output until it contains `text` or the child closes it. True if found.
  bool wait_for_output(const std::string& text) {
    char buf[4096];
    while (output_.find(text) == std::string::npos) {
      const ssize_t n = read(out_fd_, buf, sizeof buf);
      if (n <= 0) {
        return false;
      }
      output_.append(buf, static_cast<std::size_t>(n));
    }
    return true;
  }
  void signal(int sig) { kill(pid_, sig); }
  /// Waits for exit, collecting the rest of the output. Returns the exit code (128+sig if
  /// killed).
  int wait() {
    wait_for_output(std::string(1, '\0'));  // drain to EOF
    int st = 0;
    waitpid(pid_, &st, 0);
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return status_;
  }
  [[nodiscard]] const std::string& output() const { return output_; }

 private:
  pid_t pid_{-1};
  int out_fd_{-1};
  int status_{-1};
  std::string output_;
};

}  // namespace edm::test
