#include "edm/machining/located_yaml.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>
#include <unordered_map>

namespace edm::machining::yaml {

namespace {

constexpr std::string_view kTagStr = "tag:yaml.org,2002:str";
constexpr std::size_t kMaxShownChars = 40;

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

// Consumes [0-9]+ from s at i; true if at least one digit was read.
bool eat_digits(std::string_view s, std::size_t& i) noexcept {
  const std::size_t start = i;
  while (i < s.size() && is_digit(s[i])) {
    ++i;
  }
  return i > start;
}

bool is_int_text(std::string_view s) noexcept {
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) {
    ++i;
  }
  return eat_digits(s, i) && i == s.size();
}

// [-+]? ( \.[0-9]+ | [0-9]+ (\.[0-9]*)? ) ([eE][-+]?[0-9]+)?
bool is_real_text(std::string_view s) noexcept {
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) {
    ++i;
  }
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (!eat_digits(s, i)) {
      return false;
    }
  } else {
    if (!eat_digits(s, i)) {
      return false;
    }
    if (i < s.size() && s[i] == '.') {
      ++i;
      eat_digits(s, i);
    }
  }
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) {
      ++i;
    }
    if (!eat_digits(s, i)) {
      return false;
    }
  }
  return i == s.size();
}

bool is_non_finite_text(std::string_view s) noexcept {
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) {
    s.remove_prefix(1);
  }
  return s == ".inf" || s == ".Inf" || s == ".INF" || s == ".nan" || s == ".NaN" || s == ".NAN";
}

// from_chars rejects a leading '+', YAML allows it.
std::string_view strip_plus(std::string_view s) noexcept {
  if (!s.empty() && s[0] == '+') {
    s.remove_prefix(1);
  }
  return s;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + cost});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string join(std::initializer_list<std::string_view> items) {
  std::string out;
  for (std::string_view s : items) {
    if (!out.empty()) {
      out += ", ";
    }
    out += s;
  }
  return out;
}

}  // namespace

std::string quote(std::string_view text) {
  // Control bytes would garble a terminal; long values would drown the message.
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMaxShownChars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += (c < 0x20 || c == 0x7f) ? '?' : text[i];
  }
  if (text.size() > kMaxShownChars) {
    out += "...";
  }
  out += "'";
  return out;
}

ScalarKind classify_plain(std::string_view text) noexcept {
  if (text.empty() || text == "~" || text == "null" || text == "Null" || text == "NULL") {
    return ScalarKind::kNull;
  }
  if (text == "true" || text == "false") {
    return ScalarKind::kBool;
  }
  if (is_int_text(text)) {
    return ScalarKind::kInt;
  }
  if (is_real_text(text)) {
    return ScalarKind::kReal;
  }
  if (is_non_finite_text(text)) {
    return ScalarKind::kNonFinite;
  }
  return ScalarKind::kString;
}

bool is_identifier(std::string_view s) noexcept {
  if (s.empty() || is_digit(s[0])) {
    return false;
  }
  return std::all_of(s.begin(), s.end(), [](char c) {
    return is_digit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
  });
}

bool is_dotted_name(std::string_view s, int min_parts, int max_parts) noexcept {
  int parts = 0;
  while (true) {
    const std::size_t dot = s.find('.');
    if (!is_identifier(s.substr(0, dot))) {
      return false;
    }
    ++parts;
    if (dot == std::string_view::npos) {
      break;
    }
    s.remove_prefix(dot + 1);
  }
  return parts >= min_parts && parts <= max_parts;
}

std::string join_path(const std::string& parent, std::string_view key) {
  if (parent.empty()) {
    return std::string(key);
  }
  std::string out = parent;
  out += '.';
  out += key;
  return out;
}

const Field* MapView::find(std::string_view key) const noexcept {
  for (const Field& f : fields) {
    if (f.key == key) {
      return &f;
    }
  }
  return nullptr;
}

SourceLoc Reader::loc(const YAML::Mark& mark) const {
  if (mark.line < 0 || mark.column < 0) {
    return {file_, 0, 0};
  }
  return {file_, mark.line + 1, mark.column + 1};
}

void Reader::error(const Value& at, const std::string& message) { error(at.loc, at.path, message); }

void Reader::error(const SourceLoc& at, const std::string& path, const std::string& message) {
  sink_.error(at, path.empty() ? message : path + ": " + message);
}

bool Reader::is_quoted(const YAML::Node& node) {
  return node.Tag() == "!" || node.Tag() == kTagStr;
}

std::string Reader::describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Scalar: return quote(node.Scalar());
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined: break;
  }
  return "nothing (null)";
}

std::optional<MapView> Reader::map(const Value& v, std::initializer_list<std::string_view> allowed,
                                   std::string_view duplicate_note) {
  if (!v.node.IsMap()) {
    error(v, "expected a map, got " + describe(v.node) +
                 (v.node.IsNull() ? " (write {} for an empty map)" : ""));
    return std::nullopt;
  }
  MapView m{v, {}, {}};
  std::unordered_map<std::string, int> first_line;  // every key seen, known or not
  // Range-for keeps yaml-cpp's by-value iterator_value alive; it->first would dangle.
  for (const auto& kv : v.node) {
    const YAML::Node& key_node = kv.first;
    SourceLoc key_loc = loc(key_node);
    if (key_loc.line == 0) {
      key_loc = v.loc;
    }
    if (!key_node.IsScalar()) {
      error(key_loc, v.path, "keys must be plain strings, got " + describe(key_node));
      continue;
    }
    const std::string& key = key_node.Scalar();
    const auto [seen, inserted] = first_line.emplace(key, key_loc.line);
    if (!inserted) {
      // yaml-cpp keeps both entries silently; a repeated key is almost always a paste error.
      error(key_loc, v.path,
            "duplicate key " + quote(key) + " (first at line " + std::to_string(seen->second) +
                ")" + std::string(duplicate_note));
      continue;
    }
    if (allowed.size() != 0 && std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string msg = "unknown key " + quote(key);
      if (key == "<<") {
        msg += " (YAML merge keys are not supported)";
      } else {
        std::string_view best;
        std::size_t best_d = std::numeric_limits<std::size_t>::max();
        for (std::string_view a : allowed) {
          const std::size_t d = edit_distance(key, a);
          if (d < best_d) {
            best_d = d;
            best = a;
          }
        }
        if (best_d <= 2 && best_d < key.size()) {
          msg += ", did you mean '" + std::string(best) + "'?";
          m.suggested.emplace_back(best);
        }
      }
      msg += " (allowed keys: " + join(allowed) + ")";
      error(key_loc, v.path, msg);
      continue;
    }
    const YAML::Node& value = kv.second;
    SourceLoc value_loc = loc(value);
    // An empty value's mark is the next token, often on a later line: point at the key instead.
    if (value_loc.line == 0 || (value.IsNull() && value_loc.line != key_loc.line)) {
      value_loc = key_loc;
    }
    m.fields.push_back({key, key_loc, {value, value_loc, join_path(v.path, key)}});
  }
  return m;
}

std::optional<std::vector<Value>> Reader::list(const Value& v) {
  if (!v.node.IsSequence()) {
    error(v, "expected a list, got " + describe(v.node) +
                 (v.node.IsNull() ? " (write [] for an empty list)" : ""));
    return std::nullopt;
  }
  std::vector<Value> out;
  out.reserve(v.node.size());
  std::size_t i = 0;
  for (const auto& element : v.node) {
    SourceLoc l = loc(element);
    if (l.line == 0) {
      l = v.loc;
    }
    out.push_back({element, l, v.path + "[" + std::to_string(i++) + "]"});
  }
  return out;
}

const Field* Reader::require(const MapView& m, std::string_view key) {
  const Field* f = m.find(key);
  // A misspelt required key was already reported with a suggestion; one message is enough.
  if (f == nullptr && std::find(m.suggested.begin(), m.suggested.end(), key) == m.suggested.end()) {
    error(m.self, "missing required key '" + std::string(key) + "'");
  }
  return f;
}

bool Reader::scalar(const Value& v, const char* expected) {
  if (!v.node.IsScalar()) {
    error(v, std::string("expected ") + expected + ", got " + describe(v.node));
    return false;
  }
  const std::string& tag = v.node.Tag();
  if (tag != "?" && tag != "!" && tag != kTagStr) {
    error(v, "explicit tag " + quote(tag) + " is not supported");
    return false;
  }
  return true;
}

std::optional<std::string> Reader::string(const Value& v, bool allow_empty) {
  if (!scalar(v, "a string")) {
    return std::nullopt;
  }
  if (!allow_empty && v.node.Scalar().empty()) {
    error(v, "must not be empty");
    return std::nullopt;
  }
  return v.node.Scalar();
}

std::optional<std::int64_t> Reader::integer(const Value& v, std::int64_t min, std::int64_t max) {
  if (!scalar(v, "an integer")) {
    return std::nullopt;
  }
  const std::string& text = v.node.Scalar();
  const ScalarKind kind = is_quoted(v.node) ? ScalarKind::kString : classify_plain(text);
  if (kind != ScalarKind::kInt) {
    error(v, "expected an integer, got " +
                 std::string(kind == ScalarKind::kString ? "the string " : "") + quote(text));
    return std::nullopt;
  }
  const std::string_view digits = strip_plus(text);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const bool parsed = ec == std::errc{} && end == digits.data() + digits.size();
  if (!parsed || value < min || value > max) {
    if (max == std::numeric_limits<std::int64_t>::max()) {
      error(v, "must be >= " + std::to_string(min) + " (got " + text + ")");
    } else {
      error(v, "must be in " + std::to_string(min) + ".." + std::to_string(max) + " (got " + text +
                   ")");
    }
    return std::nullopt;
  }
  return value;
}

std::optional<double> Reader::real(const Value& v) {
  if (!scalar(v, "a number")) {
    return std::nullopt;
  }
  const std::string& text = v.node.Scalar();
  const ScalarKind kind = is_quoted(v.node) ? ScalarKind::kString : classify_plain(text);
  if (kind == ScalarKind::kNonFinite) {
    error(v, "must be a finite number (got " + quote(text) + ")");
    return std::nullopt;
  }
  if (kind != ScalarKind::kInt && kind != ScalarKind::kReal) {
    error(v, "expected a number, got " +
                 std::string(kind == ScalarKind::kString ? "the string " : "") + quote(text));
    return std::nullopt;
  }
  const std::string_view digits = strip_plus(text);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value)) {
    error(v, "number " + quote(text) + " is out of range");
    return std::nullopt;
  }
  return value;
}

std::optional<std::string> Reader::choice(const Value& v,
                                          std::initializer_list<std::string_view> choices) {
  std::optional<std::string> s = string(v, true);
  if (!s) {
    return std::nullopt;
  }
  if (std::find(choices.begin(), choices.end(), *s) == choices.end()) {
    error(v, "must be one of " + join(choices) + " (got " + quote(*s) + ")");
    return std::nullopt;
  }
  return s;
}

}  // namespace edm::machining::yaml
