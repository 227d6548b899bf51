#pragma once
// A HAL session for tests (docs/hal.md "Tests"): `halrun -I -f FILE` as a child, its halcmd
// reading further commands from a pipe; torn down by `exit` (halrun then unloads everything) and,
// if that does not end it in time, SIGKILL to its group and `halrun -U`. As root, halrun's
// rtapi_app needs RTAPI_UID (65534, nobody) and an RTAPI_FIFO_PATH that user can write: a file in
// a temporary directory open to all. build/bin is put first on PATH, for `loadusr edm-sim-hal`.
// The hal tests share one HAL (there is one per machine): ctest runs them under RESOURCE_LOCK hal.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "edm/apps/subprocess.hpp"
#include "edm/hal/component.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace edm::hal::test {

using namespace std::chrono_literals;
using Env = std::vector<std::pair<std::string, std::string>>;

inline const std::string kSourceDir = EDM_SOURCE_DIR;
inline const std::string kBinDir = std::filesystem::path(EDM_EDMPLC_PATH).parent_path().string();

/// The environment every HAL process of a test gets (rtapi_app's, halcmd's, edmplc's).
inline Env hal_env(const std::string& fifo_dir) {
  Env env;
  const char* path = std::getenv("PATH");
  env.emplace_back("PATH", kBinDir + ":" + (path != nullptr ? path : "/usr/bin:/bin"));
  if (geteuid() == 0) {
    env.emplace_back("RTAPI_UID", "65534");
    env.emplace_back("RTAPI_FIFO_PATH", fifo_dir + "/rtapi_fifo");
  }
  return env;
}

/// Polls `done` every `every` until it is true or `timeout` passes.
template <class F>
bool poll_until(F done, std::chrono::milliseconds timeout, std::chrono::milliseconds every = 20ms) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(every);  // the polling interval, not a wait for a thread
  }
}

class HalSession {
 public:
  /// Starts `halrun -I -f hal_file` (cwd: the test's; paths in the file relative to the source
  /// tree are run from there: halrun is started in kSourceDir by `cd`).
  explicit HalSession(const std::string& hal_file) : dir_("edm-hal-test") {
    ::chmod(dir_.path().c_str(), 0777);  // RTAPI_UID's user writes its fifo here
    env_ = hal_env(dir_.path().string());
    if (hal_running()) {
      error_ = "a HAL session is already running (halrun -U ends it)";
      return;
    }
    apps::SpawnOptions o;
    o.in = apps::Stream::kPipe;
    o.out = o.err = apps::Stream::kFile;
    o.out_file = o.err_file = dir_.file("halrun.log");
    o.set_env = env_;
    proc_ = std::make_unique<apps::Process>(
        std::vector<std::string>{"bash", "-c",
                                 "cd " + kSourceDir + " && exec halrun -I -f " + hal_file},
        o);
    if (!proc_->started()) {
      error_ = proc_->error();
      return;
    }
    if (!poll_until([&] { return hal_running() || proc_->poll().has_value(); }, 20s)) {
      error_ = "HAL did not come up in 20 s:\n" + log();
    } else if (proc_->poll()) {
      error_ = "halrun ended:\n" + log();
    }
  }
  ~HalSession() { stop(); }
  HalSession(const HalSession&) = delete;
  HalSession& operator=(const HalSession&) = delete;

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const Env& env() const { return env_; }
  [[nodiscard]] std::string log() const { return edm::test::read_file(dir_.file("halrun.log")); }
  [[nodiscard]] std::string file(const std::string& name) const { return dir_.file(name); }

  /// Runs `halcmd args...` (10 s at most); its stdout, or nullopt when it failed.
  std::optional<std::string> halcmd(const std::vector<std::string>& args) const {
    std::vector<std::string> argv{"halcmd"};
    argv.insert(argv.end(), args.begin(), args.end());
    apps::SpawnOptions o;
    o.set_env = env_;
    o.err = apps::Stream::kStdout;
    const apps::RunResult r = apps::run(argv, o, 10s);
    if (!r.error.empty() || r.exit_code != 0) return std::nullopt;
    return r.out;
  }
  /// A signal's value as halcmd prints it (`gets`), trimmed; nullopt when there is none.
  std::optional<std::string> gets(const std::string& signal) const {
    auto out = halcmd({"-s", "gets", signal});
    if (!out) return std::nullopt;
    while (!out->empty() && (out->back() == '\n' || out->back() == ' ')) out->pop_back();
    return out;
  }
  /// One command line to the session's interactive halcmd.
  bool command(const std::string& line) { return proc_ && proc_->write_input(line + "\n"); }

  void stop() {
    if (!proc_ || proc_->ended()) return;
    proc_->write_input("exit\n");
    proc_->close_input();
    if (!proc_->wait(15s)) proc_->kill();
    if (hal_running()) {  // halrun did not clean up (killed): force the realtime exit
      apps::SpawnOptions o;
      o.set_env = env_;
      o.out = apps::Stream::kNull;
      (void)apps::run({"halrun", "-U"}, o, 20s);
    }
  }

 private:
  edm::test::TempDir dir_;
  Env env_;
  std::unique_ptr<apps::Process> proc_;
  std::string error_;
};

}  // namespace edm::hal::test
