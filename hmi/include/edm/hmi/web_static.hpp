#pragma once
// Static files of the browser page for `edmhmi serve` (docs/web.md): maps a request target to a
// file under the web root without ever leaving it, names its Content-Type and its caching.
//
// index.html (and any other non-hashed file) is served `Cache-Control: no-cache` so a new build is
// seen on the next load; Vite's content-hashed files under /assets/ are immutable for a year.
//
// Non-RT; pure functions (thread-safe).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace edm::hmi {

/// Largest static file served (bytes); a bigger one is answered 500 (the page is far smaller).
inline constexpr std::size_t kMaxStaticFileBytes = std::size_t{16} << 20;

/// The file a request target names under `root`, or nullopt when the target is not a plain
/// absolute path (query and fragment are dropped first), has a `..`, `.` or empty segment after
/// percent-decoding, a NUL, a backslash, a bad %-escape, or resolves (symlinks followed) outside
/// `root`. "/" and directory targets map to their index.html. Does not check that the file exists.
std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view target);

/// "text/html; charset=utf-8", "text/javascript; charset=utf-8", … by extension;
/// "application/octet-stream" for unknown ones.
std::string_view content_type_for(const std::filesystem::path& file);

/// The Cache-Control value for a served file (see above).
std::string_view cache_control_for(std::string_view target);

}  // namespace edm::hmi
