#pragma once
// Where edmhmi finds the shipped machine configs (`check` without --machine) and the built page
// (`serve` without --web-root), with no path compiled in (docs/deploy.md), first found wins:
//   1. --data-dir DIR, else $EDM_DATA_DIR: DIR/machines/..., DIR/web/
//   2. installed: <exe>/../share/edmplc (the .debs: /usr/share/edmplc), the same layout;
//   3. the build tree: <exe>/../CMakeCache.txt names the source tree: <source>/config/machines/...,
//      and the page built into <build>/web.
// Thread safety: plain functions of their arguments (self_exe() reads /proc/self/exe).

#include <filesystem>
#include <string>

namespace edmhmi {

struct DataPaths {
  std::filesystem::path config_dir;  // holds machines/drill-sim.yaml; empty: none found
  std::filesystem::path web_root;    // holds index.html; empty: none found
  std::string origin;                // how they were found, for messages
};

/// `flag` (--data-dir) or `env` ($EDM_DATA_DIR, may be null) when set, else beside `exe`.
[[nodiscard]] DataPaths find_data_paths(const std::string& flag, const char* env,
                                        const std::filesystem::path& exe);

/// This executable's path (/proc/self/exe), or empty.
[[nodiscard]] std::filesystem::path self_exe();

/// The shipped machine edmhmi checks against by default.
inline constexpr const char* kDefaultMachine = "machines/drill-sim.yaml";

}  // namespace edmhmi
