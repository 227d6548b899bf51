#include "doc_markers.hpp"

#include <algorithm>
#include <optional>
#include <string_view>

namespace edm::paramdoc {

namespace {

constexpr std::string_view kOpen = "<!-- params:";
constexpr std::string_view kClose = "<!-- /params:";
constexpr std::string_view kEnd = " -->";

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) {
    s.remove_prefix(1);
  }
  while (!s.empty() &&
         (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) {
    s.remove_suffix(1);
  }
  return s;
}

// The type named by a marker line of the given kind ("<!-- params:Gain -->" → "Gain").
std::optional<std::string> marker(std::string_view line, std::string_view prefix) {
  line = trim(line);
  if (!line.starts_with(prefix) || !line.ends_with(kEnd) ||
      line.size() <= prefix.size() + kEnd.size()) {
    return std::nullopt;
  }
  return std::string(trim(line.substr(prefix.size(), line.size() - prefix.size() - kEnd.size())));
}

std::vector<std::string_view> lines_of(const std::string& text) {
  std::vector<std::string_view> lines;
  std::string_view rest = text;
  while (!rest.empty()) {
    const std::size_t nl = rest.find('\n');
    const std::size_t len = nl == std::string_view::npos ? rest.size() : nl + 1;
    lines.push_back(rest.substr(0, len));
    rest.remove_prefix(len);
  }
  return lines;
}

}  // namespace

SpliceResult splice_tables(const std::string& text,
                           const std::map<std::string, std::string>& wanted) {
  SpliceResult r;
  const std::vector<std::string_view> lines = lines_of(text);
  std::size_t i = 0;
  while (i < lines.size()) {
    const std::string where = "line " + std::to_string(i + 1) + ": ";
    const std::optional<std::string> open = marker(lines[i], kOpen);
    if (!open) {
      if (const auto close = marker(lines[i], kClose)) {
        r.errors.push_back(where + "closing marker for '" + *close + "' without its opening one");
      }
      r.text += lines[i++];
      continue;
    }
    // Find the matching close; an opening marker first means this pair is not closed.
    std::size_t j = i + 1;
    while (j < lines.size() && !marker(lines[j], kClose) && !marker(lines[j], kOpen)) {
      ++j;
    }
    if (j == lines.size() || marker(lines[j], kClose) != open) {
      r.errors.push_back(where + "'" + *open + "' has no closing marker <!-- /params:" + *open +
                         " --> before the next marker");
      r.text += lines[i++];
      continue;
    }
    if (std::find(r.found.begin(), r.found.end(), *open) != r.found.end()) {
      r.errors.push_back(where + "a second section for '" + *open + "'");
    }
    r.found.push_back(*open);
    std::string body;
    for (std::size_t k = i + 1; k < j; ++k) {
      body += lines[k];
    }
    r.text += lines[i];
    const auto it = wanted.find(*open);
    if (it == wanted.end()) {
      r.errors.push_back(where + "no registered block or driver type '" + *open + "'");
      r.text += body;
    } else {
      if (body != it->second) {
        r.stale.push_back(*open);
      }
      r.text += it->second;
    }
    r.text += lines[j];
    i = j + 1;
  }
  return r;
}

}  // namespace edm::paramdoc
