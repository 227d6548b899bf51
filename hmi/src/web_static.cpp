#include "edm/hmi/web_static.hpp"

#include <array>
#include <system_error>
#include <utility>

namespace edm::hmi {

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Percent-decodes one path; nullopt on a bad escape or a decoded NUL.
std::optional<std::string> percent_decode(std::string_view in) {
  std::string out;
  out.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    char c = in[i];
    if (c == '%') {
      if (i + 2 >= in.size()) return std::nullopt;
      const int hi = hex_value(in[i + 1]), lo = hex_value(in[i + 2]);
      if (hi < 0 || lo < 0) return std::nullopt;
      c = static_cast<char>(hi * 16 + lo);
      i += 2;
    }
    if (c == '\0') return std::nullopt;
    out.push_back(c);
  }
  return out;
}

bool is_within(const std::filesystem::path& root, const std::filesystem::path& p) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (q == p.end() || *r != *q) return false;
  }
  return true;
}

}  // namespace

std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view target) {
  if (const auto cut = target.find_first_of("?#"); cut != std::string_view::npos) {
    target = target.substr(0, cut);
  }
  if (target.empty() || target.front() != '/') return std::nullopt;
  const std::optional<std::string> decoded = percent_decode(target);
  if (!decoded) return std::nullopt;
  std::filesystem::path rel;
  std::string_view rest(*decoded);
  rest.remove_prefix(1);
  bool directory = rest.empty();
  while (!rest.empty()) {
    const auto slash = rest.find('/');
    const std::string_view seg = rest.substr(0, slash);
    rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
    if (slash != std::string_view::npos && rest.empty()) directory = true;  // trailing '/'
    if (seg.empty() || seg == "." || seg == ".." || seg.find('\\') != std::string_view::npos) {
      return std::nullopt;
    }
    rel /= std::string(seg);
  }
  std::error_code ec;
  const std::filesystem::path canon_root = std::filesystem::weakly_canonical(root, ec);
  if (ec) return std::nullopt;
  std::filesystem::path file = canon_root / rel;
  if (directory || std::filesystem::is_directory(file, ec)) file /= "index.html";
  // Symlinks inside the root must not lead out of it.
  const std::filesystem::path canon = std::filesystem::weakly_canonical(file, ec);
  if (ec || !is_within(canon_root, canon)) return std::nullopt;
  return canon;
}

std::string_view content_type_for(const std::filesystem::path& file) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 12> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".map", "application/json"},
      {".woff2", "font/woff2"},
      {".webmanifest", "application/manifest+json"},
  }};
  const std::string ext = file.extension().string();
  for (const auto& [e, type] : kTypes) {
    if (ext == e) return type;
  }
  return "application/octet-stream";
}

std::string_view cache_control_for(std::string_view target) {
  return target.starts_with("/assets/") ? "public, max-age=31536000, immutable" : "no-cache";
}

}  // namespace edm::hmi
