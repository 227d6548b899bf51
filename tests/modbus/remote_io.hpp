#pragma once
// The pymodbus remote I/O of tests/modbus/remote_io.py as a child process: a Modbus TCP server
// on a free loopback port whose tables a test sets and reads through the child's stdin.

#include <string>

#include "support/free_port.hpp"
#include "support/subprocess.hpp"

namespace edm::test {

class RemoteIo {
 public:
  explicit RemoteIo(int port = free_port()) : port_(port) { start(); }

  void start() {
    edm::apps::SpawnOptions o;
    o.in = edm::apps::Stream::kPipe;
    proc_ = edm::apps::Process(
        {"/usr/bin/python3", std::string(EDM_TEST_DATA_DIR) + "/modbus/remote_io.py", "--port",
         std::to_string(port_)},
        o);
    ready_ = proc_.read_until("READY " + std::to_string(port_), std::chrono::seconds(20));
  }
  /// SIGKILL: the server goes away without a word (a coupler losing power).
  void kill() { proc_.kill(); }

  [[nodiscard]] bool ready() const { return ready_; }
  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] std::string output() const { return proc_.output(); }

  /// table: di, co, ir, hr (0-based addresses).
  bool set(const std::string& table, int address, int value) {
    const std::size_t before = count("ok\n");
    proc_.write_input("set " + table + " " + std::to_string(address) + " " + std::to_string(value) +
                      "\n");
    for (int i = 0; i < 100 && count("ok\n") == before; ++i) {
      proc_.read_some(std::chrono::milliseconds(100));
    }
    return count("ok\n") > before;
  }
  /// The value, or -1 when there was no answer.
  int get(const std::string& table, int address) {
    const std::string key = table + " " + std::to_string(address) + " ";
    const std::size_t from = proc_.output().size();
    proc_.write_input("get " + table + " " + std::to_string(address) + "\n");
    for (int i = 0; i < 100; ++i) {
      const std::size_t at = proc_.output().find(key, from);
      if (at != std::string::npos && proc_.output().find('\n', at) != std::string::npos) {
        return std::stoi(proc_.output().substr(at + key.size()));
      }
      proc_.read_some(std::chrono::milliseconds(100));
    }
    return -1;
  }

 private:
  [[nodiscard]] std::size_t count(const std::string& s) const {
    std::size_t n = 0;
    for (std::size_t at = proc_.output().find(s); at != std::string::npos;
         at = proc_.output().find(s, at + 1)) {
      ++n;
    }
    return n;
  }

  int port_;
  edm::apps::Process proc_;
  bool ready_{false};
};

}  // namespace edm::test
