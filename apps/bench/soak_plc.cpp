#include "soak_plc.hpp"

#include <signal.h>

#include <fstream>

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

std::string PlcProcess::start(const std::vector<std::string>& args, const fs::path& log) {
  edm::apps::SpawnOptions o;
  o.out = edm::apps::Stream::kFile;
  o.out_file = log;
  process_ = edm::apps::Process(args, o);
  return process_.error();
}

bool PlcProcess::stop(std::chrono::seconds limit) {
  if (!running()) {
    return exited_cleanly();
  }
  // edmplc stops in order on SIGINT (safe state, stats written); SIGKILL after `limit`.
  process_.stop(SIGINT, limit);
  return exited_cleanly();
}

}  // namespace edm::bench::soak
