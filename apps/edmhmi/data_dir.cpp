#include "data_dir.hpp"

#include <fstream>
#include <string_view>
#include <system_error>
#include <utility>

namespace edmhmi {

namespace fs = std::filesystem;

namespace {

/// The source tree a CMake build tree was configured from (CMAKE_HOME_DIRECTORY in its cache),
/// or empty.
fs::path source_dir_of_build_tree(const fs::path& build_dir) {
  std::ifstream in(build_dir / "CMakeCache.txt");
  constexpr std::string_view kKey = "CMAKE_HOME_DIRECTORY:INTERNAL=";
  std::string line;
  for (int n = 0; n < 100000 && std::getline(in, line); ++n) {
    if (line.starts_with(kKey)) {
      return fs::path(line.substr(kKey.size()));
    }
  }
  return {};
}

DataPaths from_data_dir(const fs::path& dir, std::string origin) {
  return DataPaths{dir, dir / "web", std::move(origin)};
}

}  // namespace

DataPaths find_data_paths(const std::string& flag, const char* env, const fs::path& exe) {
  if (!flag.empty()) {
    return from_data_dir(flag, "--data-dir");
  }
  if (env != nullptr && *env != '\0') {
    return from_data_dir(env, "$EDM_DATA_DIR");
  }
  if (exe.empty()) {
    return {};
  }
  std::error_code ec;
  const fs::path prefix = exe.parent_path().parent_path();
  if (const fs::path installed = prefix / "share" / "edmplc"; fs::is_directory(installed, ec)) {
    return from_data_dir(installed, "the install prefix");
  }
  // Only a build tree has a CMakeCache.txt beside its bin/: tests and ./edm demo run from there.
  if (const fs::path source = source_dir_of_build_tree(prefix); !source.empty()) {
    return DataPaths{source / "config", prefix / "web", "the build tree"};
  }
  return {};
}

fs::path self_exe() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path{} : p;
}

}  // namespace edmhmi
