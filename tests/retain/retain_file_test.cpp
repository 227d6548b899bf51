#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <system_error>

#include "edm/runtime/retain.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;

using TempDir = edm::test::TempDir;
using edm::test::read_file;
using edm::test::write_file;

// A body followed by its correct end line: isolates the check under test from the checksum.
std::string with_end(const std::string& body) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08x", crc32_ieee(body));
  return body + "end " + hex + "\n";
}

RetainMap sample_map() {
  return {
      {"drill.counter.holes", RetainValue::make_int(17)},
      {"drill.electrode.length_left", RetainValue::make_real(123.456)},
      {"drill.seq.done", RetainValue::make_bool(true)},
  };
}

TEST(RetainCrc, matches_the_ieee_check_value) {
  EXPECT_EQ(crc32_ieee("123456789"), 0xCBF43926U);
  EXPECT_EQ(crc32_ieee(""), 0x00000000U);
  EXPECT_EQ(crc32_ieee("a"), 0xE8B7BE43U);
}

// Bytes written before the CRC moved to Boost.CRC (issue 18): files already on disk must load.
TEST(RetainCrc, a_file_written_by_the_hand_written_crc_still_loads) {
  const TempDir dir;
  const std::string path = dir.file("old.retain");
  write_file(path,
             "edmplc-retain 1\n"
             "drill.counter.holes LINT 17\n"
             "drill.electrode.length_left LREAL 123.456\n"
             "drill.seq.done BOOL 1\n"
             "end 5ad6925c\n");
  const RetainLoadResult r = load_retain_file(path);
  EXPECT_EQ(r.status, RetainLoadStatus::kLoaded) << r.warning;
  EXPECT_EQ(r.values, sample_map());
}

TEST(RetainValueEq, compares_reals_bit_for_bit_and_ignores_inactive_fields) {
  EXPECT_NE(RetainValue::make_real(0.0), RetainValue::make_real(-0.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(RetainValue::make_real(nan), RetainValue::make_real(nan));
  EXPECT_NE(RetainValue::make_int(1), RetainValue::make_real(1.0));
  RetainValue a = RetainValue::make_int(5);
  a.r = 3.0;  // inactive field
  EXPECT_EQ(a, RetainValue::make_int(5));
}

TEST(RetainFile, format_is_the_documented_text) {
  const std::string text = format_retain_file(sample_map());
  EXPECT_EQ(text,
            "edmplc-retain 1\n"
            "drill.counter.holes LINT 17\n"
            "drill.electrode.length_left LREAL 123.456\n"
            "drill.seq.done BOOL 1\n"
            "end 5ad6925c\n");
}

TEST(RetainFile, round_trips_every_type_and_extreme_reals_exactly) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  using L = std::numeric_limits<double>;
  const RetainMap in = {
      {"b.false", RetainValue::make_bool(false)},
      {"b.true", RetainValue::make_bool(true)},
      {"i.zero", RetainValue::make_int(0)},
      {"i.minus_one", RetainValue::make_int(-1)},
      {"i.min", RetainValue::make_int(std::numeric_limits<std::int64_t>::min())},
      {"i.max", RetainValue::make_int(std::numeric_limits<std::int64_t>::max())},
      {"r.tenth", RetainValue::make_real(0.1)},
      {"r.neg_zero", RetainValue::make_real(-0.0)},
      {"r.zero", RetainValue::make_real(0.0)},
      {"r.tiny", RetainValue::make_real(1e-300)},
      {"r.denorm", RetainValue::make_real(L::denorm_min())},
      {"r.max", RetainValue::make_real(L::max())},
      {"r.lowest", RetainValue::make_real(L::lowest())},
      {"r.third", RetainValue::make_real(1.0 / 3.0)},
      {"r.inf", RetainValue::make_real(L::infinity())},
      {"r.neg_inf", RetainValue::make_real(-L::infinity())},
      {"r.nan", RetainValue::make_real(L::quiet_NaN())},
      {"x.odd-but/valid:name[3]", RetainValue::make_int(3)},
  };
  write_retain_file_atomic(path, in);
  const RetainLoadResult out = load_retain_file(path);
  EXPECT_EQ(out.warning, "");
  ASSERT_EQ(out.values.size(), in.size());
  for (const auto& [name, value] : in) {
    ASSERT_TRUE(out.values.contains(name)) << name;
    EXPECT_EQ(out.values.at(name), value) << name;  // bitwise for reals
  }
  EXPECT_TRUE(std::signbit(out.values.at("r.neg_zero").r));
  EXPECT_TRUE(std::isnan(out.values.at("r.nan").r));
  // Deterministic: the same map gives the same bytes, and rewriting what was read changes nothing.
  const std::string bytes = read_file(path);
  EXPECT_EQ(bytes, format_retain_file(in));
  write_retain_file_atomic(path, out.values);
  EXPECT_EQ(read_file(path), bytes);
  // No temp file is left after a successful write.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) {
    ++entries;
  }
  EXPECT_EQ(entries, 1U);
}

TEST(RetainFile, empty_map_round_trips) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  write_retain_file_atomic(path, {});
  const RetainLoadResult out = load_retain_file(path);
  EXPECT_EQ(out.warning, "");
  EXPECT_TRUE(out.values.empty());
}

TEST(RetainFile, missing_file_gives_warning_with_path) {
  TempDir dir;
  const std::string path = dir.file("does-not-exist.retain");
  const RetainLoadResult out = load_retain_file(path);
  EXPECT_TRUE(out.values.empty());
  EXPECT_NE(out.warning.find(path), std::string::npos) << out.warning;
  EXPECT_NE(out.warning.find("not found"), std::string::npos) << out.warning;
}

TEST(RetainFile, directory_and_empty_file_give_warnings) {
  TempDir dir;
  RetainLoadResult out = load_retain_file(dir.path().string());
  EXPECT_TRUE(out.values.empty());
  EXPECT_NE(out.warning.find("not a regular file"), std::string::npos) << out.warning;
  const std::string path = dir.file("empty");
  write_file(path, "");
  out = load_retain_file(path);
  EXPECT_NE(out.warning.find("empty file"), std::string::npos) << out.warning;
}

TEST(RetainFile, every_truncation_is_detected) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  const std::string good = format_retain_file(sample_map());
  for (std::size_t len = 0; len < good.size(); ++len) {
    write_file(path, good.substr(0, len));
    RetainLoadResult out;
    ASSERT_NO_THROW(out = load_retain_file(path));
    EXPECT_TRUE(out.values.empty()) << "len " << len;
    EXPECT_NE(out.warning.find(path), std::string::npos) << "len " << len << ": " << out.warning;
  }
}

TEST(RetainFile, every_single_byte_corruption_is_detected) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  const std::string good = format_retain_file(sample_map());
  for (std::size_t at = 0; at < good.size(); ++at) {
    for (const unsigned mask : {0x01U, 0x20U, 0x80U, 0xFFU}) {
      std::string bad = good;
      bad[at] = static_cast<char>(static_cast<unsigned char>(bad[at]) ^ mask);
      write_file(path, bad);
      RetainLoadResult out;
      ASSERT_NO_THROW(out = load_retain_file(path));
      EXPECT_TRUE(out.values.empty()) << "offset " << at << " mask " << mask;
      EXPECT_FALSE(out.warning.empty()) << "offset " << at << " mask " << mask;
    }
  }
}

struct BadCase {
  const char* what;
  std::string text;
  const char* expected;  // substring of the warning
};

TEST(RetainFile, malformed_files_are_rejected_with_a_precise_warning) {
  const std::string h = "edmplc-retain 1\n";
  const std::string good = with_end(h + "a.b.c LINT 1\n");
  const BadCase cases[] = {
      {"wrong header", with_end("edmplc-retian 1\na.b.c LINT 1\n"), "line 1: not a retain file"},
      {"future version", with_end("edmplc-retain 2\na.b.c LINT 1\n"), "unsupported version"},
      {"duplicate name", with_end(h + "a.b.c LINT 1\na.b.c LINT 2\n"),
       "line 3: duplicate name 'a.b.c'"},
      {"unknown type", with_end(h + "a.b.c REAL 1\n"), "line 2: unknown type 'REAL'"},
      {"bool not 0/1", with_end(h + "a.b.c BOOL 2\n"), "line 2: bad BOOL value '2'"},
      {"fractional int", with_end(h + "a.b.c LINT 1.5\n"), "line 2: bad LINT value"},
      {"int overflow", with_end(h + "a.b.c LINT 9223372036854775808\n"), "bad LINT value"},
      {"bad real", with_end(h + "a.b.c LREAL 1.0x\n"), "line 2: bad LREAL value"},
      {"empty value", with_end(h + "a.b.c LREAL \n"), "bad LREAL value"},
      {"two fields", with_end(h + "a.b.c LINT\n"), "line 2: expected 'NAME TYPE VALUE'"},
      {"double space", with_end(h + "a.b.c  LINT 1\n"), "line 2: unknown type ''"},
      {"extra field", with_end(h + "a.b.c LINT 1 2\n"), "line 2: bad LINT value '1 2'"},
      {"empty line", with_end(h + "\n"), "line 2: expected"},
      {"control char in name", with_end(h + "a.\tc LINT 1\n"), "line 2: bad name"},
      {"CRLF line", with_end(h + "a.b.c LINT 1\r\n"), "line 2: bad LINT value"},
      {"missing end", h + "a.b.c LINT 1\n", "missing end line"},
      {"trailing garbage", good + "x\n", "line 4: data after the end line"},
      {"trailing garbage without newline", good + "x", "no newline"},
      {"end twice", good + "end 00000000\n", "checksum mismatch"},
      {"uppercase checksum", h + "end " + "0A0B0C0D\n", "bad end line"},
      {"short checksum", h + "end 1234\n", "bad end line"},
      {"wrong checksum", h + "a.b.c LINT 1\nend 00000000\n", "checksum mismatch"},
  };
  for (const BadCase& c : cases) {
    const RetainLoadResult out = parse_retain_file(c.text);
    EXPECT_TRUE(out.values.empty()) << c.what;
    EXPECT_NE(out.warning.find(c.expected), std::string::npos)
        << c.what << ": got '" << out.warning << "'";
  }
  EXPECT_EQ(parse_retain_file(good).warning, "");
  // A name "end" in the body is a normal variable: only the last line is the end line.
  const RetainLoadResult named_end = parse_retain_file(with_end(h + "end LINT 4\n"));
  EXPECT_EQ(named_end.warning, "");
  EXPECT_EQ(named_end.values.at("end"), RetainValue::make_int(4));
}

TEST(RetainFile, invalid_names_are_refused_before_touching_the_disk) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  for (const char* name : {"", "a b", "a\nb", "tab\there", "caf\xc3\xa9"}) {
    EXPECT_THROW(write_retain_file_atomic(path, {{name, RetainValue::make_int(1)}}),
                 std::invalid_argument)
        << name;
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(RetainFile, write_into_missing_or_non_directory_parent_throws_system_error_with_path) {
  TempDir dir;
  const std::string not_a_dir = dir.file("plain");
  write_file(not_a_dir, "x");
  for (const std::string& path : {dir.file("missing/retain.txt"), not_a_dir + "/retain.txt"}) {
    try {
      write_retain_file_atomic(path, sample_map());
      ADD_FAILURE() << "no exception for " << path;
    } catch (const std::system_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(RetainFile, failed_rename_removes_the_temp_file) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  fs::create_directory(path);            // rename of a file over a directory fails (EISDIR)
  fs::create_directory(path + "/keep");  // non-empty, so no filesystem lets the rename through
  EXPECT_THROW(write_retain_file_atomic(path, sample_map()), std::system_error);
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) {
    ++entries;
    EXPECT_EQ(e.path().filename(), "retain.txt");
  }
  EXPECT_EQ(entries, 1U);
}

TEST(RetainFile, read_only_directory_throws_system_error) {
  TempDir dir;
  const fs::path ro = dir.path() / "ro";
  fs::create_directory(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(ro.c_str(), W_OK) == 0) {
    fs::permissions(ro, fs::perms::owner_all);
    GTEST_SKIP() << "running with privileges that ignore directory permissions";
  }
  EXPECT_THROW(write_retain_file_atomic((ro / "retain.txt").string(), sample_map()),
               std::system_error);
  fs::permissions(ro, fs::perms::owner_all);
}

TEST(RetainFile, remove_stale_temps_removes_only_other_writers_temp_files) {
  TempDir dir;
  const std::string path = dir.file("retain.txt");
  write_retain_file_atomic(path, sample_map());
  write_file(path + ".tmp.12345", "partial");
  write_file(path + ".tmp.999999", "partial");
  write_file(path + ".tmp." + std::to_string(::getpid()), "ours");
  write_file(path + ".tmp.notapid", "unrelated");
  write_file(dir.file("other.txt.tmp.1"), "unrelated");
  EXPECT_EQ(remove_stale_retain_temps(path), 2U);
  EXPECT_FALSE(fs::exists(path + ".tmp.12345"));
  EXPECT_FALSE(fs::exists(path + ".tmp.999999"));
  EXPECT_TRUE(fs::exists(path + ".tmp." + std::to_string(::getpid())));
  EXPECT_TRUE(fs::exists(path + ".tmp.notapid"));
  EXPECT_TRUE(fs::exists(dir.file("other.txt.tmp.1")));
  EXPECT_EQ(load_retain_file(path).warning, "");
  EXPECT_EQ(remove_stale_retain_temps(dir.file("nowhere/retain.txt")), 0U);
}

}  // namespace
}  // namespace edm::rt
