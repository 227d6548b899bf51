#pragma once
// Whole-file reads and writes for test code (not RT-safe: allocates; thread-safe: no shared state).

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

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

#ifdef EDM_SOURCE_DIR
/// Makes `dir`/fragments a link to config/machines/fragments: a shipped machine's config written
/// (edited) into `dir` then finds the fragments it includes (docs/config.md "Fragments").
inline void link_machine_fragments(const std::string& dir) {
  const std::filesystem::path link = std::filesystem::path(dir) / "fragments";
  std::error_code ec;
  if (!std::filesystem::exists(link, ec)) {
    std::filesystem::create_directory_symlink(
        std::filesystem::path(EDM_SOURCE_DIR) / "config/machines/fragments", link, ec);
  }
  if (ec) {
    throw std::runtime_error("cannot link " + link.string() + ": " + ec.message());
  }
}
#endif

#ifdef EDM_TEST_DATA_DIR
/// The text of tests/data/<name> with each `{{key}}` in it replaced by its value: for configs that
/// several tests share or that differ only in a few values. Throws when the file is missing or
/// empty, or a key is not in it.
inline std::string test_data(
    const std::string& name,
    std::initializer_list<std::pair<std::string_view, std::string>> values = {}) {
  std::string text = read_file(std::string(EDM_TEST_DATA_DIR) + "/data/" + name);
  if (text.empty()) {
    throw std::runtime_error("tests/data/" + name + ": missing or empty");
  }
  for (const auto& [key, value] : values) {
    const std::string marker = "{{" + std::string(key) + "}}";
    std::size_t at = text.find(marker);
    if (at == std::string::npos) {
      throw std::runtime_error("tests/data/" + name + ": no " + marker);
    }
    for (; at != std::string::npos; at = text.find(marker, at + value.size())) {
      text.replace(at, marker.size(), value);
    }
  }
  return text;
}
#endif

}  // namespace edm::test
