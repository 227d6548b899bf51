#pragma once
// Reading a whole file, for the main()s and bench drivers that edit a shipped config before a run.
// Non-RT (allocates, throws); thread-safe (no shared state).

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace edm::apps {

/// The whole file, bytes as they are. Throws std::runtime_error("<path>: cannot read").
inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::runtime_error(path + ": cannot read");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace edm::apps
