#pragma once
// One bounded reader for every file a user names (part programs, configs, token files): it
// refuses anything but a regular file before reading (a FIFO cannot hang it, /dev/zero cannot
// exhaust memory, a directory gets a located message) and never reads more than a limit.
//
// Errors read "PATH:1:1: message" (the file as a whole is wrong), so every tool reports them in
// the same file:line:col form as its other input errors.
//
// RT-safety: none (file I/O, allocation); load time and offline tools only.
// Thread-safety: reentrant.

#include <cstddef>
#include <string>

namespace edm::machining {

/// Limits of the files users hand us; far above any real one (docs/config.md, docs/gcode.md).
inline constexpr std::size_t kMaxPartProgramBytes = std::size_t{64} << 20;  // G-code: 64 MiB
inline constexpr std::size_t kMaxConfigBytes = std::size_t{4} << 20;        // YAML: 4 MiB
inline constexpr std::size_t kMaxTokenFileBytes = std::size_t{4} << 10;     // a token: 4 KiB

struct BoundedRead {
  std::string text;     // the whole file when ok()
  std::string problem;  // why not, e.g. "not a regular file (a FIFO)"; empty when ok()
  std::string error;    // "PATH:1:1: <problem>"
  [[nodiscard]] bool ok() const noexcept { return problem.empty(); }
};

/// Reads the regular file `path` whole if it holds at most `max_bytes` bytes. Opens without
/// blocking (O_NONBLOCK) and checks the type with fstat on the open descriptor (no race with a
/// swap), then reads at most max_bytes + 1 bytes, so a file that grows is refused too. `what`
/// names the kind of file in the size message ("part program", "config"). Never throws.
[[nodiscard]] BoundedRead read_bounded_file(const std::string& path, std::size_t max_bytes,
                                            const char* what) noexcept;

}  // namespace edm::machining
