// The retain file against a hostile or broken file system (issue 17 item 3): the writer never
// follows a planted link nor replaces anything but a regular file; the reader never hangs on a
// FIFO, never reads a device or a huge file, and survives any bytes.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <system_error>

#include "edm/runtime/retain.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;
using edm::test::read_file;
using edm::test::TempDir;
using edm::test::write_file;

const RetainMap kValues = {{"p.counter.holes", RetainValue::make_int(17)},
                           {"p.electrode.left_mm", RetainValue::make_real(123.5)}};

TEST(RetainHostile, planted_link_at_the_old_predictable_temp_name_is_not_followed) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  const std::string victim = dir.file("victim.txt");
  write_file(victim, "precious\n");
  // The name older builds wrote to: path.tmp.<pid>. A link there must not be written through.
  const std::string old_tmp = path + ".tmp." + std::to_string(::getpid());
  ASSERT_EQ(::symlink(victim.c_str(), old_tmp.c_str()), 0);
  write_retain_file_atomic(path, kValues);
  EXPECT_EQ(read_file(victim), "precious\n");
  EXPECT_TRUE(fs::is_symlink(old_tmp));
  const RetainLoadResult r = load_retain_file(path);
  EXPECT_EQ(r.status, RetainLoadStatus::kLoaded) << r.warning;
  EXPECT_EQ(r.values, kValues);
}

TEST(RetainHostile, temp_names_are_unpredictable_and_the_file_is_private) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  write_retain_file_atomic(path, kValues);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600U) << "retained data is not for other users";
  // Two writers in one process never share a temp name: a stale temp left under our own pid
  // (as a crashed thread would) neither blocks nor is reused by the next write.
  const std::string ours = path + ".tmp." + std::to_string(::getpid()) + ".0123456789abcdef";
  write_file(ours, "left over");
  write_retain_file_atomic(path, kValues);
  EXPECT_EQ(read_file(ours), "left over");
}

TEST(RetainHostile, writer_refuses_anything_but_a_regular_file) {
  TempDir dir;
  const std::string fifo = dir.file("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string subdir = dir.file("adir");
  fs::create_directory(subdir);
  const std::string target = dir.file("target.txt");
  write_file(target, "target\n");
  const std::string link = dir.file("link");
  ASSERT_EQ(::symlink(target.c_str(), link.c_str()), 0);
  for (const std::string& p : {fifo, subdir, link}) {
    SCOPED_TRACE(p);
    try {
      write_retain_file_atomic(p, kValues);
      ADD_FAILURE() << "wrote over " << p;
    } catch (const std::system_error& e) {
      EXPECT_NE(std::string(e.what()).find("must be a regular file"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_TRUE(fs::is_directory(subdir));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(read_file(target), "target\n");
  // No temp file was left behind by the refusals.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) {
    ++entries;
  }
  EXPECT_EQ(entries, 4U);
}

TEST(RetainHostile, dev_null_is_refused_without_touching_it) {
  // Only the checks run here (no attempted write: as root, a regression would replace /dev/null).
  EXPECT_NE(retain_target_problem("/dev/null").find("a device"), std::string::npos);
  const RetainLoadResult r = load_retain_file("/dev/null");
  EXPECT_EQ(r.status, RetainLoadStatus::kNotRegular) << r.warning;
  EXPECT_EQ(retain_target_problem("/nonexistent-dir/retain.txt"), "");
}

TEST(RetainHostile, reader_never_blocks_on_a_fifo_nor_reads_a_device_or_a_link) {
  TempDir dir;
  const std::string fifo = dir.file("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  RetainLoadResult r = load_retain_file(fifo);  // would block forever without O_NONBLOCK
  EXPECT_EQ(r.status, RetainLoadStatus::kNotRegular);
  EXPECT_NE(r.warning.find("a FIFO"), std::string::npos) << r.warning;

  r = load_retain_file("/dev/zero");  // would exhaust memory if read to EOF
  EXPECT_EQ(r.status, RetainLoadStatus::kNotRegular) << r.warning;

  const std::string real = dir.file("real.txt");
  write_retain_file_atomic(real, kValues);
  const std::string link = dir.file("link.txt");
  ASSERT_EQ(::symlink(real.c_str(), link.c_str()), 0);
  r = load_retain_file(link);
  EXPECT_EQ(r.status, RetainLoadStatus::kNotRegular);
  EXPECT_NE(r.warning.find("symbolic link"), std::string::npos) << r.warning;
  EXPECT_TRUE(r.values.empty());
}

TEST(RetainHostile, huge_file_is_refused_unread) {
  TempDir dir;
  const std::string path = dir.file("huge.txt");
  {
    std::ofstream out(path, std::ios::binary);
    out << "edmplc-retain 1\n";
  }
  fs::resize_file(path, std::uintmax_t{1} << 40);  // sparse 1 TiB: reading it would never end
  const RetainLoadResult r = load_retain_file(path);
  EXPECT_EQ(r.status, RetainLoadStatus::kCorrupt);
  EXPECT_NE(r.warning.find("too large"), std::string::npos) << r.warning;

  const std::string big(kMaxRetainFileBytes + 1, '\n');
  const RetainLoadResult p = parse_retain_file(big);
  EXPECT_EQ(p.status, RetainLoadStatus::kCorrupt);
  EXPECT_NE(p.warning.find("too large"), std::string::npos) << p.warning;
}

TEST(RetainHostile, missing_and_corrupt_are_told_apart) {
  TempDir dir;
  EXPECT_EQ(load_retain_file(dir.file("none")).status, RetainLoadStatus::kMissing);
  write_file(dir.file("bad"), "edmplc-retain 1\ngarbage\n");
  EXPECT_EQ(load_retain_file(dir.file("bad")).status, RetainLoadStatus::kCorrupt);
}

TEST(RetainHostile, set_aside_keeps_every_corrupt_copy) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  write_file(path, "first bad\n");
  EXPECT_EQ(set_aside_retain_file(path), path + ".corrupt");
  write_file(path, "second bad\n");
  EXPECT_EQ(set_aside_retain_file(path), path + ".corrupt.1");
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(read_file(path + ".corrupt"), "first bad\n");
  EXPECT_EQ(read_file(path + ".corrupt.1"), "second bad\n");
}

// Seeded random mutations of a good file and random bytes: the pure parser never crashes and
// either loads everything (only possible with a matching checksum) or nothing, with a reason.
TEST(RetainHostile, parser_survives_random_bytes) {
  const std::string good = format_retain_file(kValues);
  std::mt19937_64 rng(0xED17'0003ULL);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string text;
    if (trial % 2 == 0) {
      text = good;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits; ++e) {
        const std::size_t at = rng() % (text.size() + 1);
        switch (rng() % 3) {
          case 0:
            if (at < text.size()) text[at] = static_cast<char>(byte(rng));
            break;
          case 1: text.insert(at, 1, static_cast<char>(byte(rng))); break;
          default: text.erase(at, rng() % 8); break;
        }
      }
    } else {
      text.resize(rng() % 200);
      for (char& c : text) c = static_cast<char>(byte(rng));
    }
    const RetainLoadResult r = parse_retain_file(text);
    if (r.warning.empty()) {
      EXPECT_EQ(r.status, RetainLoadStatus::kLoaded);
    } else {
      EXPECT_EQ(r.status, RetainLoadStatus::kCorrupt);
      EXPECT_TRUE(r.values.empty()) << "half-applied: " << r.warning;
    }
  }
}

}  // namespace
}  // namespace edm::rt
