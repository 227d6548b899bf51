#pragma once
// Whole-file reads and writes for test code (not RT-safe: allocates; thread-safe: no shared state).

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

namespace edm::test {

/// Every byte of the file at `path`; empty when it cannot be opened.
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Replaces the file at `path` with `bytes`. Removes it first: ext4 flushes a file truncated over
/// old data on close (auto_da_alloc), which makes byte-by-byte sweeps slow.
inline void write_file(const std::string& path, const std::string& bytes) {
  std::error_code ec;
  std::filesystem::remove(path, ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

}  // namespace edm::test
