#include "edm/runtime/log_escape.hpp"

namespace edm::rt {

void append_log_quoted(std::string& out, std::string_view text, std::size_t max_bytes, char quote) {
  static constexpr char kHex[] = "0123456789abcdef";
  const std::string_view shown = text.substr(0, max_bytes);
  out.reserve(out.size() + shown.size() + 4);
  out.push_back(quote);
  for (const char ch : shown) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == quote || ch == '\\') {
      out.push_back('\\');
      out.push_back(ch);
    } else if (c >= 0x20 && c <= 0x7e) {
      out.push_back(ch);
    } else {
      out.append("\\x");
      out.push_back(kHex[c >> 4]);
      out.push_back(kHex[c & 0xF]);
    }
  }
  out.push_back(quote);
  if (text.size() > shown.size()) {
    out.append("\xe2\x80\xa6");  // "…"
  }
}

std::string log_quote(std::string_view text, std::size_t max_bytes, char quote) {
  std::string s;
  append_log_quoted(s, text, max_bytes, quote);
  return s;
}

bool is_printable_ascii(std::string_view text) noexcept {
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

}  // namespace edm::rt
