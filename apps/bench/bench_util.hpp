#pragma once
// What the bench drivers share: a temp directory, a tool run the drivers' way (edm::apps::run with
// stdout captured and stderr into a file), failure texts with the tool's last lines. Non-RT.
// Not thread-safe: from the main thread.

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "edm/apps/subprocess.hpp"

namespace edm::bench {

namespace fs = std::filesystem;

/// Removes the mkdtemp directory (and the stats/stderr files in it) when main returns.
class TempDir {
 public:
  TempDir() {
    std::string templ = (fs::path("/tmp") / "edm-bench-jitter.XXXXXX").string();
    if (mkdtemp(templ.data()) != nullptr) {
      path_ = templ;
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) {
      fs::remove_all(path_, ec);
    }
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

using ChildResult = edm::apps::RunResult;
using edm::apps::find_in_path;
using edm::apps::install_stop_handlers;

/// Runs args[0] (no shell) with stdin from /dev/null, stdout captured, stderr into `err_path`,
/// optionally pinned with all its threads to `cpu`. Stopped (SIGTERM, 2 s later SIGKILL) after
/// `timeout` or on SIGINT/SIGTERM.
ChildResult run_child(const std::vector<std::string>& args, const fs::path& err_path,
                      std::optional<int> cpu, std::chrono::seconds timeout);

/// Empty when the child ran and exited 0; otherwise what went wrong, with its stderr's tail.
std::string child_failure(const std::string& tool, const ChildResult& r, const fs::path& err);

/// The whole file; empty if it cannot be read.
std::string read_file(const fs::path& path);

/// The last `n` lines of `text`, indented with "    | ", for error messages.
std::string tail_lines(const std::string& text, std::size_t n);

}  // namespace edm::bench
