#include "bench_util.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace edm::bench {

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

ChildResult run_child(const std::vector<std::string>& args, const fs::path& err_path,
                      std::optional<int> cpu, std::chrono::seconds timeout) {
  edm::apps::SpawnOptions o;
  o.err = edm::apps::Stream::kFile;
  o.err_file = err_path;
  o.cpu = cpu;
  return edm::apps::run(args, o, timeout);
}

std::string child_failure(const std::string& tool, const ChildResult& r, const fs::path& err) {
  const std::string what = r.failure(tool);
  if (what.empty()) {
    return {};
  }
  return fmt::format("{}\n{}{}", what, tail_lines(read_file(err), 15), tail_lines(r.out, 5));
}

}  // namespace edm::bench
