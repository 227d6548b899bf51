#include "edm/runtime/retain.hpp"

// Retain files on disk: the guarded read, the atomic write (temp file, fsync, rename, fsync dir),
// setting a corrupt file aside and removing stale temp files. The format is retain_format.cpp.

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace edm::rt {
namespace {

std::string errno_text(int err) { return std::generic_category().message(err); }

[[noreturn]] void throw_io(int err, const std::string& path, std::string_view step) {
  throw std::system_error(err, std::generic_category(),
                          fmt::format("retain file '{}': {}", path, step));
}

// Closes the fd on every path out of the writer.
class Fd {
 public:
  explicit Fd(int fd) noexcept : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) {
      ::close(fd_);
    }
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  [[nodiscard]] int get() const noexcept { return fd_; }
  int release() noexcept { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

// A failure after the temp file exists must not leave it behind.
[[noreturn]] void fail_and_unlink(Fd& fd, const std::string& tmp, const std::string& path,
                                  std::string_view step) {
  const int err = errno;
  ::close(fd.release());
  ::unlink(tmp.c_str());
  throw_io(err, path, step);
}

std::string temp_prefix(const std::string& path) { return path + ".tmp."; }

// An unpredictable suffix: another local user cannot plant a link at the temp name in advance.
std::string random_hex16() {
  std::uint64_t r = 0;
  auto* p = reinterpret_cast<unsigned char*>(&r);
  std::size_t got = 0;
  while (got < sizeof r) {
    const ssize_t n = ::getrandom(p + got, sizeof r - got, 0);
    if (n < 0) {
      if (errno == EINTR) {
        continue;
      }
      // No entropy source: O_EXCL still refuses anything planted, so mix what we have.
      r ^= static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) *
           0x9E3779B97F4A7C15ULL;
      break;
    }
    got += static_cast<std::size_t>(n);
  }
  return fmt::format("{:016x}", r);
}

std::string_view kind_of(mode_t mode) {
  if (S_ISDIR(mode)) {
    return "a directory";
  }
  if (S_ISLNK(mode)) {
    return "a symbolic link";
  }
  if (S_ISFIFO(mode)) {
    return "a FIFO";
  }
  if (S_ISCHR(mode) || S_ISBLK(mode)) {
    return "a device";
  }
  if (S_ISSOCK(mode)) {
    return "a socket";
  }
  return "not a regular file";
}

std::string dir_of(const std::string& path) {
  std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? std::string(".") : dir;
}

}  // namespace

RetainLoadResult load_retain_file(const std::string& path) noexcept {
  auto fail = [&path](RetainLoadStatus status, std::string_view problem) {
    return RetainLoadResult{{}, fmt::format("retain file '{}': {}", path, problem), status};
  };
  try {
    // O_NONBLOCK: a FIFO must not hang the start; O_NOFOLLOW: a link is refused, not followed.
    Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY));
    if (fd.get() < 0) {
      const int err = errno;
      if (err == ENOENT) {
        return fail(RetainLoadStatus::kMissing, "not found");
      }
      if (err == ELOOP) {
        return fail(RetainLoadStatus::kNotRegular, "a symbolic link; not followed");
      }
      return fail(RetainLoadStatus::kUnreadable, "cannot open: " + errno_text(err));
    }
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) {
      return fail(RetainLoadStatus::kUnreadable, "cannot stat: " + errno_text(errno));
    }
    if (!S_ISREG(st.st_mode)) {
      return fail(RetainLoadStatus::kNotRegular,
                  fmt::format("not a regular file ({})", kind_of(st.st_mode)));
    }
    if (static_cast<std::uint64_t>(st.st_size) > kMaxRetainFileBytes) {
      return fail(RetainLoadStatus::kCorrupt,
                  fmt::format("too large ({} bytes, at most {})", st.st_size, kMaxRetainFileBytes));
    }
    std::string text;
    std::array<char, 8192> buf{};
    for (;;) {
      const ssize_t n = ::read(fd.get(), buf.data(), buf.size());
      if (n < 0) {
        if (errno == EINTR) {
          continue;
        }
        return fail(RetainLoadStatus::kUnreadable, "read error: " + errno_text(errno));
      }
      if (n == 0) {
        break;
      }
      text.append(buf.data(), static_cast<std::size_t>(n));
      // The file may grow after fstat: the bound holds for what is read, too.
      if (text.size() > kMaxRetainFileBytes) {
        return fail(RetainLoadStatus::kCorrupt,
                    fmt::format("too large (more than {} bytes)", kMaxRetainFileBytes));
      }
    }
    RetainLoadResult result = parse_retain_file(text);
    if (!result.warning.empty()) {
      return fail(RetainLoadStatus::kCorrupt, result.warning);
    }
    return result;
  } catch (const std::exception& e) {
    return fail(RetainLoadStatus::kUnreadable, fmt::format("internal error: {}", e.what()));
  }
}

std::string retain_target_problem(const std::string& path) noexcept {
  try {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) {
      return {};  // missing (first start) or unreachable: the open that follows says precisely
    }
    if (S_ISREG(st.st_mode)) {
      return {};
    }
    return fmt::format(
        "'{}' is {}; the retain file must be a regular file (refusing to read "
        "or replace it)",
        path, kind_of(st.st_mode));
  } catch (...) {
    return "cannot check the retain file";
  }
}

void write_retain_file_atomic(const std::string& path, const RetainMap& values) {
  write_file_atomic(path, format_retain_file(values));
}

void write_file_atomic(const std::string& path, std::string_view text) {
  // Checked before any temp file exists: a device, FIFO, directory or link is never renamed over.
  if (const std::string problem = retain_target_problem(path); !problem.empty()) {
    throw_io(EINVAL, path, problem);
  }
  const std::string prefix = temp_prefix(path) + std::to_string(::getpid()) + ".";
  std::string tmp;
  int raw_fd = -1;
  // O_EXCL|O_NOFOLLOW: whatever sits at the name (a planted link, a file) is never opened.
  for (int attempt = 0; attempt < 16 && raw_fd < 0; ++attempt) {
    tmp = prefix + random_hex16();
    raw_fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (raw_fd < 0 && errno != EEXIST) {
      break;
    }
  }
  Fd fd(raw_fd);
  if (fd.get() < 0) {
    throw_io(errno, path, fmt::format("cannot create temp file '{}'", tmp));
  }
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd.get(), text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) {
        continue;
      }
      fail_and_unlink(fd, tmp, path, "write to temp file");
    }
    done += static_cast<std::size_t>(n);
  }
  // The data must be on disk before the rename makes it visible, or a power cut could leave a
  // renamed but empty file.
  if (::fsync(fd.get()) != 0) {
    fail_and_unlink(fd, tmp, path, "fsync temp file");
  }
  if (::close(fd.release()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw_io(err, path, "close temp file");
  }
  // Again just before the rename: narrows the window in which something else appears there.
  if (const std::string problem = retain_target_problem(path); !problem.empty()) {
    ::unlink(tmp.c_str());
    throw_io(EINVAL, path, problem);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw_io(err, path, fmt::format("rename '{}' over it", tmp));
  }
  // Makes the rename itself durable.
  const std::string dir = dir_of(path);
  Fd dfd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dfd.get() < 0) {
    throw_io(errno, path, fmt::format("open directory '{}' to fsync", dir));
  }
  if (::fsync(dfd.get()) != 0) {
    throw_io(errno, path, fmt::format("fsync directory '{}'", dir));
  }
}

std::string set_aside_retain_file(const std::string& path) {
  for (int n = 0; n < 100; ++n) {
    const std::string to = path + ".corrupt" + (n == 0 ? std::string() : fmt::format(".{}", n));
    struct stat st {};
    if (::lstat(to.c_str(), &st) == 0) {
      continue;  // an earlier corrupt copy: keep it too
    }
    if (::rename(path.c_str(), to.c_str()) != 0) {
      throw_io(errno, path, fmt::format("rename to '{}'", to));
    }
    return to;
  }
  throw_io(EEXIST, path, "set aside: .corrupt .. .corrupt.99 all exist");
}

std::size_t remove_stale_retain_temps(const std::string& path) noexcept {
  std::size_t removed = 0;
  try {
    const std::string prefix = std::filesystem::path(temp_prefix(path)).filename().string();
    const std::string own_pid = std::to_string(::getpid());
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir_of(path), ec), end; !ec && it != end;
         it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (!name.starts_with(prefix)) {
        continue;
      }
      // `<pid>` (older builds) or `<pid>.<16 hex>`.
      std::string_view pid = std::string_view(name).substr(prefix.size());
      if (const std::size_t dot = pid.find('.'); dot != std::string_view::npos) {
        const std::string_view hex = pid.substr(dot + 1);
        if (hex.size() != 16 || hex.find_first_not_of("0123456789abcdef") != std::string::npos) {
          continue;
        }
        pid = pid.substr(0, dot);
      }
      if (pid.empty() || pid.find_first_not_of("0123456789") != std::string_view::npos ||
          pid == own_pid) {
        continue;
      }
      std::error_code rm_ec;
      if (std::filesystem::remove(it->path(), rm_ec)) {
        ++removed;
      }
    }
  } catch (...) {
    // A leftover temp file only costs disk space; never fail the caller for it.
  }
  return removed;
}

}  // namespace edm::rt
