#include "edm/runtime/retain.hpp"

// The retain file format (retain.hpp): names, values, the CRC line, format and parse. No I/O;
// the guarded read and the atomic write are in retain_file.cpp.

#include <fmt/format.h>

#include <array>
#include <bit>
#include <boost/crc.hpp>
#include <charconv>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace edm::rt {
namespace {

constexpr std::string_view kHeader = "edmplc-retain 1";
constexpr std::string_view kHeaderMagic = "edmplc-retain ";
constexpr std::string_view kEndPrefix = "end ";

std::optional<RetainType> parse_type(std::string_view s) {
  if (s == "BOOL") {
    return RetainType::kBool;
  }
  if (s == "LINT") {
    return RetainType::kInt;
  }
  if (s == "LREAL") {
    return RetainType::kReal;
  }
  return std::nullopt;
}

void append_value(std::string& out, const RetainValue& v) {
  std::array<char, 64> buf{};
  std::to_chars_result res{};
  switch (v.type) {
    case RetainType::kBool: out += v.b ? '1' : '0'; return;
    case RetainType::kInt: res = std::to_chars(buf.data(), buf.data() + buf.size(), v.i); break;
    case RetainType::kReal:
      // Shortest representation that parses back to the same bits (C++17 to_chars guarantee).
      res = std::to_chars(buf.data(), buf.data() + buf.size(), v.r);
      break;
  }
  out.append(buf.data(), res.ptr);
}

std::optional<RetainValue> parse_value(RetainType t, std::string_view s) {
  const char* first = s.data();
  const char* last = s.data() + s.size();
  switch (t) {
    case RetainType::kBool:
      if (s == "0" || s == "1") {
        return RetainValue::make_bool(s == "1");
      }
      return std::nullopt;
    case RetainType::kInt: {
      std::int64_t v{};
      auto [p, ec] = std::from_chars(first, last, v);
      if (ec != std::errc{} || p != last || s.empty()) {
        return std::nullopt;
      }
      return RetainValue::make_int(v);
    }
    case RetainType::kReal: {
      double v{};
      auto [p, ec] = std::from_chars(first, last, v);
      if (ec != std::errc{} || p != last || s.empty()) {
        return std::nullopt;
      }
      return RetainValue::make_real(v);
    }
  }
  return std::nullopt;
}

// For warnings: a garbled line may hold control bytes or be huge.
std::string printable(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (const char c : s.substr(0, kMax)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7F) ? c : '?';
  }
  if (s.size() > kMax) {
    out += "...";
  }
  return out;
}

}  // namespace

std::string_view to_string(RetainType t) noexcept {
  switch (t) {
    case RetainType::kBool: return "BOOL";
    case RetainType::kInt: return "LINT";
    case RetainType::kReal: return "LREAL";
  }
  return "?";
}

bool operator==(const RetainValue& a, const RetainValue& b) noexcept {
  if (a.type != b.type) {
    return false;
  }
  switch (a.type) {
    case RetainType::kBool: return a.b == b.b;
    case RetainType::kInt: return a.i == b.i;
    case RetainType::kReal:
      return std::bit_cast<std::uint64_t>(a.r) == std::bit_cast<std::uint64_t>(b.r);
  }
  return false;
}

bool is_valid_retain_name(std::string_view name) noexcept {
  if (name.empty()) {
    return false;
  }
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u >= 0x7F) {
      return false;
    }
  }
  return true;
}

std::uint32_t crc32_ieee(std::string_view data) noexcept {
  boost::crc_32_type crc;
  crc.process_bytes(data.data(), data.size());
  return crc.checksum();
}

std::string format_retain_file(const RetainMap& values) {
  std::string out;
  out.reserve(32 + values.size() * 48);
  out += kHeader;
  out += '\n';
  for (const auto& [name, value] : values) {
    if (!is_valid_retain_name(name)) {
      throw std::invalid_argument(
          fmt::format("retain: invalid variable name '{}' (empty or has whitespace or control "
                      "characters)",
                      printable(name)));
    }
    out += name;
    out += ' ';
    out += to_string(value.type);
    out += ' ';
    append_value(out, value);
    out += '\n';
  }
  out += fmt::format("{}{:08x}\n", kEndPrefix, crc32_ieee(out));
  return out;
}

RetainLoadResult parse_retain_file(std::string_view text) noexcept {
  auto fail = [](std::string message) {
    return RetainLoadResult{{}, std::move(message), RetainLoadStatus::kCorrupt};
  };
  try {
    if (text.size() > kMaxRetainFileBytes) {
      return fail(
          fmt::format("too large ({} bytes, at most {})", text.size(), kMaxRetainFileBytes));
    }
    if (text.empty()) {
      return fail("empty file");
    }
    if (text.back() != '\n') {
      return fail("truncated (last line has no newline)");
    }
    // Split into lines without their '\n'; the text ends with '\n', so no partial line is left.
    std::vector<std::string_view> lines;
    for (std::size_t pos = 0; pos < text.size();) {
      const std::size_t nl = text.find('\n', pos);
      lines.push_back(text.substr(pos, nl - pos));
      pos = nl + 1;
    }
    if (lines.front() != kHeader) {
      if (lines.front().starts_with(kHeaderMagic)) {
        return fail(fmt::format("line 1: unsupported version '{}' (this build reads '{}')",
                                printable(lines.front()), kHeader));
      }
      return fail(fmt::format("line 1: not a retain file (expected '{}', found '{}')", kHeader,
                              printable(lines.front())));
    }
    // The end line must be the last one; check the checksum before trusting any value line.
    const std::string_view end_line = lines.back();
    if (lines.size() < 2 || !end_line.starts_with(kEndPrefix)) {
      for (std::size_t n = 1; n + 1 < lines.size(); ++n) {
        if (lines[n].starts_with(kEndPrefix)) {
          return fail(fmt::format("line {}: data after the end line", n + 2));
        }
      }
      return fail("missing end line (file truncated?)");
    }
    const std::string_view hex = end_line.substr(kEndPrefix.size());
    std::uint32_t stored = 0;
    const bool hex_ok =
        hex.size() == 8 && hex.find_first_not_of("0123456789abcdef") == std::string_view::npos &&
        std::from_chars(hex.data(), hex.data() + hex.size(), stored, 16).ec == std::errc{};
    if (!hex_ok) {
      return fail(fmt::format("line {}: bad end line '{}'", lines.size(), printable(end_line)));
    }
    const std::size_t body_bytes = text.size() - end_line.size() - 1;
    const std::uint32_t computed = crc32_ieee(text.substr(0, body_bytes));
    if (stored != computed) {
      return fail(
          fmt::format("checksum mismatch (stored {:08x}, computed {:08x})", stored, computed));
    }
    RetainLoadResult result;
    for (std::size_t n = 1; n + 1 < lines.size(); ++n) {
      const std::string_view line = lines[n];
      const std::size_t line_no = n + 1;
      const std::size_t s1 = line.find(' ');
      const std::size_t s2 = s1 == std::string_view::npos ? s1 : line.find(' ', s1 + 1);
      if (s2 == std::string_view::npos) {
        return fail(fmt::format("line {}: expected 'NAME TYPE VALUE', found '{}'", line_no,
                                printable(line)));
      }
      const std::string_view name = line.substr(0, s1);
      const std::string_view type_text = line.substr(s1 + 1, s2 - s1 - 1);
      const std::string_view value_text = line.substr(s2 + 1);
      if (!is_valid_retain_name(name)) {
        return fail(fmt::format("line {}: bad name '{}'", line_no, printable(name)));
      }
      const std::optional<RetainType> type = parse_type(type_text);
      if (!type) {
        return fail(fmt::format("line {}: unknown type '{}'", line_no, printable(type_text)));
      }
      const std::optional<RetainValue> value = parse_value(*type, value_text);
      if (!value) {
        return fail(fmt::format("line {}: bad {} value '{}'", line_no, to_string(*type),
                                printable(value_text)));
      }
      if (!result.values.emplace(std::string(name), *value).second) {
        return fail(fmt::format("line {}: duplicate name '{}'", line_no, printable(name)));
      }
    }
    return result;
  } catch (const std::exception& e) {
    return fail(fmt::format("internal error while parsing: {}", e.what()));
  }
}

}  // namespace edm::rt
