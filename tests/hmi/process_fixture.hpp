#pragma once
// Process tests of edmhmi against a real edmplc (virtual clock paced to a multiple of wall time,
// the bridge on a free loopback port): child processes whose stdout and stderr go to files (no
// pipe can fill up and block a child nobody reads), waits for observable state with a deadline,
// and a fixture that kills every child it started in its teardown.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "edm/apps/subprocess.hpp"
#include "edm/bridge/client.hpp"
#include "support/files.hpp"
#include "support/free_port.hpp"
#include "support/temp_dir.hpp"

namespace edm::hmi::test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using edm::test::free_port;
using edm::test::read_file;

/// Calls `done` every `every` until it returns true or `timeout` has passed. True if it did.
template <class F>
bool poll_until(F done, std::chrono::milliseconds timeout, std::chrono::milliseconds every = 20ms) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(every);  // the polling interval, not a wait for a thread
  }
}

using Env = std::vector<std::pair<std::string, std::string>>;

/// A child process (edm::apps::Process); stdout and stderr to files. The edmhmi connection
/// variables of the test's own environment are removed, then `env` is set. Killed (SIGKILL, its
/// group) and reaped when destroyed.
class Proc : public edm::apps::Process {
 public:
  Proc(const std::vector<std::string>& argv, std::string out_path, std::string err_path,
       const Env& env = {})
      : Process(argv, options(out_path, err_path, env)),
        out_path_(std::move(out_path)),
        err_path_(std::move(err_path)) {}

  [[nodiscard]] std::string out() const { return read_file(out_path_); }
  [[nodiscard]] std::string err() const { return read_file(err_path_); }

 private:
  static edm::apps::SpawnOptions options(const std::string& out, const std::string& err,
                                         const Env& env) {
    edm::apps::SpawnOptions o;
    o.out = o.err = edm::apps::Stream::kFile;
    o.out_file = out;
    o.err_file = err;
    o.unset_env = {"EDM_HOST", "EDM_PORT", "EDM_TOKEN_FILE", "EDM_TOKEN"};
    o.set_env = env;
    return o;
  }
  std::string out_path_, err_path_;
};

struct Outcome {
  int code{-1};  // -1: did not end in time (then killed)
  std::string out;
  std::string err;
};

inline const std::string kSourceDir = EDM_SOURCE_DIR;
inline const std::string kParts = kSourceDir + "/examples/parts/";
inline const std::string kDrillSim = kSourceDir + "/config/machines/drill-sim.yaml";

/// One edmplc per test (virtual clock at `kSpeed`× wall time) and the edmhmi runs against it.
/// TearDown kills every child still running.
class EdmhmiProcessTest : public ::testing::Test {
 protected:
  static constexpr const char* kSpeed = "20";

  // The fragments link: drill-sim.yaml edited into dir_ finds the fragments it includes.
  EdmhmiProcessTest() : dir_("edm-hmi-test") { edm::test::link_machine_fragments(dir_.path()); }

  void TearDown() override {
    for (auto& p : children_) p->kill();
    if (plc_) plc_->kill();
  }

  /// Starts edmplc on `config` and waits until its bridge listens and says hello (deadline, no
  /// fixed sleep). Another port is tried when the free one was taken in between.
  void start_plc(const std::string& config = kDrillSim, const std::string& token = "",
                 const edm::bridge::ClientTls& tls = {}) {
    for (int attempt = 0; attempt < 3; ++attempt) {
      port_ = free_port();
      plc_ = std::make_unique<Proc>(
          std::vector<std::string>{EDM_EDMPLC_PATH, "--config", config, "--clock", "virtual",
                                   "--speed", kSpeed, "--bridge-port", std::to_string(port_)},
          dir_.file("edmplc.out"), dir_.file("edmplc.err"));
      const auto listening = [&] {
        return (plc_->out() + plc_->err()).find("bridge: listening on") != std::string::npos;
      };
      const bool up = poll_until(
          [&] {
            if (plc_->poll()) return true;   // ended: retried or reported below
            if (!listening()) return false;  // (a connect could reach another port's owner)
            edm::bridge::Client c;
            edm::bridge::ClientOptions o;
            o.port = static_cast<std::uint16_t>(port_);
            o.token = token;
            o.tls = tls;
            o.timeout = 2000ms;
            try {
              c.connect(o);
              return true;
            } catch (const edm::bridge::ClientError&) {
              return false;
            }
          },
          20s, 25ms);
      if (up && !plc_->poll()) return;
      const std::string log = plc_->out() + plc_->err();
      if (plc_->poll() && log.find("in use") != std::string::npos) continue;
      FAIL() << "edmplc did not come up on port " << port_ << "\n" << log;
    }
    FAIL() << "edmplc found no free port";
  }

  /// The connection flags for the test's edmplc.
  [[nodiscard]] std::vector<std::string> conn() const {
    return {EDM_EDMHMI_PATH, "--host", "127.0.0.1", "--port", std::to_string(port_)};
  }

  /// Starts `edmhmi [conn] args...` without waiting (without the flags when !flags: then `env`
  /// says where edmplc is).
  Proc& spawn(const std::vector<std::string>& args, const Env& env = {}, bool flags = true) {
    std::vector<std::string> argv = flags ? conn() : std::vector<std::string>{EDM_EDMHMI_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    const std::string n = std::to_string(children_.size());
    children_.push_back(std::make_unique<Proc>(argv, dir_.file("hmi" + n + ".out"),
                                               dir_.file("hmi" + n + ".err"), env));
    return *children_.back();
  }

  /// Runs `edmhmi [conn] args...` to its end (killed after `timeout`).
  Outcome edmhmi(const std::vector<std::string>& args, const Env& env = {}, bool flags = true,
                 std::chrono::milliseconds timeout = 30s) {
    Proc& p = spawn(args, env, flags);
    Outcome o;
    if (const auto code = p.wait(timeout)) {
      o.code = *code;
    } else {
      p.kill();
    }
    o.out = p.out();
    o.err = p.err();
    return o;
  }

  /// Polls `edmhmi status` until its stdout contains `text`; returns the last output.
  Outcome status_until(const std::string& text, std::chrono::milliseconds timeout = 30s) {
    Outcome last;
    poll_until(
        [&] {
          last = edmhmi({"status"});
          return last.code == 0 && last.out.find(text) != std::string::npos;
        },
        timeout, 50ms);
    return last;
  }

  edm::test::TempDir dir_;
  int port_{0};
  std::unique_ptr<Proc> plc_;
  std::vector<std::unique_ptr<Proc>> children_;
};

/// The number after `label` (then white space) in `text`, e.g. "depth reached   15.0012 mm".
inline std::optional<double> number_after(const std::string& text, const std::string& label) {
  const auto at = text.find(label);
  if (at == std::string::npos) return std::nullopt;
  static const std::regex kNumber(R"(^\s*([-+]?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?))");
  std::smatch m;
  const std::string rest = text.substr(at + label.size());
  if (!std::regex_search(rest, m, kNumber)) return std::nullopt;
  return std::stod(m[1].str());
}

/// The value of a job report row ("  label   value"), or "" when there is no such row.
inline std::string row_value(const std::string& text, const std::string& label) {
  const std::string head = "  " + label + " ";
  std::size_t at = text.rfind(head, 0) == 0 ? 0 : text.find("\n" + head);
  if (at == std::string::npos) return "";
  if (text[at] == '\n') ++at;
  const std::size_t start = text.find_first_not_of(' ', at + head.size());
  const std::size_t end = text.find('\n', at);
  if (start == std::string::npos || start >= end) return "";
  return text.substr(start, end - start);
}

}  // namespace edm::hmi::test
