#include "edm/machining/bounded_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>

namespace edm::machining {
namespace {

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string mib(std::size_t bytes) {
  return bytes % (std::size_t{1} << 20) == 0 ? std::to_string(bytes >> 20) + " MiB"
         : bytes % 1024 == 0                 ? std::to_string(bytes >> 10) + " KiB"
                                             : std::to_string(bytes) + " bytes";
}

}  // namespace

BoundedRead read_bounded_file(const std::string& path, std::size_t max_bytes,
                              const char* what) noexcept {
  BoundedRead r;
  try {
    const auto fail = [&](const std::string& why) {
      r.text.clear();
      r.problem = why;
      r.error = path + ":1:1: " + why;
      return r;
    };
    // O_NONBLOCK: opening a FIFO must not wait for a writer; O_NOCTTY: a tty never becomes ours.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) {
      return fail(std::string("cannot open: ") + std::strerror(errno));
    }
    struct Closer {
      int fd;
      ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      return fail(std::string("cannot stat: ") + std::strerror(errno));
    }
    if (!S_ISREG(st.st_mode)) {
      return fail("not a regular file (" + kind_of(st.st_mode) + ")");
    }
    if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
      return fail(std::string(what) + " is " + std::to_string(st.st_size) +
                  " bytes; the limit is " + mib(max_bytes));
    }
    r.text.reserve(static_cast<std::size_t>(st.st_size));
    std::array<char, 65536> buf{};
    for (;;) {
      const ssize_t n = ::read(fd, buf.data(), buf.size());
      if (n < 0) {
        if (errno == EINTR) continue;
        return fail(std::string("cannot read: ") + std::strerror(errno));
      }
      if (n == 0) break;
      r.text.append(buf.data(), static_cast<std::size_t>(n));
      if (r.text.size() > max_bytes) {  // grew after fstat (a file being written, /proc)
        return fail(std::string(what) + " is larger than " + mib(max_bytes));
      }
    }
    return r;
  } catch (const std::exception& e) {
    r.text.clear();
    r.problem = std::string("cannot read: ") + e.what();
    r.error = path + ":1:1: " + r.problem;
    return r;
  }
}

}  // namespace edm::machining
