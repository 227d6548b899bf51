#pragma once
// A child process for tests (edm::apps::Process): stdout and stderr together through one pipe,
// started in its own process group, killed with it when the test ends.

#include <chrono>
#include <string>
#include <vector>

#include "edm/apps/subprocess.hpp"

namespace edm::test {

class Child : public edm::apps::Process {
 public:
  explicit Child(const std::vector<std::string>& argv) : Process(argv, merged()) {}

  /// Reads output until it contains `text`, the child closes it or 60 s pass. True if found.
  bool wait_for_output(const std::string& text) {
    return read_until(text, std::chrono::seconds(60));
  }
  /// Waits for the end (killed after 240 s, inside ctest's 300 s), the output read to its end.
  /// The exit code, or 128 + the signal.
  int wait() {
    if (const auto status = Process::wait(std::chrono::seconds(240))) return *status;
    return stop(SIGKILL);
  }

 private:
  static edm::apps::SpawnOptions merged() {
    edm::apps::SpawnOptions o;
    o.in = edm::apps::Stream::kInherit;
    return o;  // stdout into the pipe, stderr with it
  }
};

}  // namespace edm::test
