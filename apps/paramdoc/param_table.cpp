#include "param_table.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/param.hpp"
#include "edm/runtime/time.hpp"

namespace edm::paramdoc {

namespace {

using rt::ParamType;

// A table cell: a '|' would end the cell and a line break the row.
std::string cell(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '|') {
      out += "\\|";
    } else if (c == '\n') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

// As YAML would write it: the shortest text that reads back to the same double, in plain
// notation for everyday magnitudes, and with ".0" on whole numbers so a REAL looks like one.
std::string real_text(double v) {
  if (std::isnan(v)) {
    return ".nan";
  }
  if (std::isinf(v)) {
    return v > 0 ? ".inf" : "-.inf";
  }
  char buf[64];
  const double a = std::fabs(v);
  const bool plain = v == 0.0 || (a >= 1e-4 && a < 1e9);
  const auto [end, ec] = plain ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
                               : std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, ec == std::errc{} ? end : buf);
  if (plain && s.find('.') == std::string::npos) {
    s += ".0";
  }
  // "1e+09" → "1e9", "1e-05" → "1e-5".
  if (const std::size_t e = s.find('e'); e != std::string::npos) {
    std::size_t digits = e + 1;
    if (s[digits] == '+') {
      s.erase(digits, 1);
    } else if (s[digits] == '-') {
      ++digits;
    }
    while (digits + 1 < s.size() && s[digits] == '0') {
      s.erase(digits, 1);
    }
  }
  return s;
}

std::string default_text(const rt::ParamRef& ref) {
  if (ref.type == ParamType::kString) {
    return *static_cast<const std::string*>(ref.field);
  }
  const rt::ParamValue v = rt::read_param(ref);
  switch (v.type) {
    case ParamType::kBool: return v.b ? "true" : "false";
    case ParamType::kInt: return std::to_string(v.i);
    case ParamType::kReal: return real_text(v.r);
    case ParamType::kDuration:
      return v.i == 0 ? "0s" : rt::format_duration(rt::Duration{v.i});  // not "0ns"
    case ParamType::kString: break;
  }
  return {};
}

// Range (INT, REAL, TIME in seconds) and finiteness (REAL), as validation checks them.
std::string range_text(ParamType type, const rt::ParamSpec& spec) {
  if (type == ParamType::kBool || type == ParamType::kString) {
    return {};
  }
  std::string text = spec.range.text();
  const bool both_bounds = !std::isinf(spec.range.lo) && !std::isinf(spec.range.hi);
  if (type == ParamType::kDuration && !text.empty() &&
      ((!std::isinf(spec.range.lo) && spec.range.lo != 0.0) || !std::isinf(spec.range.hi))) {
    text += " s";
  }
  if (type == ParamType::kReal && spec.finite && !both_bounds) {
    text += text.empty() ? "finite" : ", finite";
  }
  return text;
}

struct Row {
  std::string name, type, unit, range, default_value, writable, description;
};

class RowCollector final : public rt::ParamVisitor {
 public:
  std::vector<Row> rows;

 protected:
  void on_param(std::string_view name, rt::ParamRef ref, rt::ParamSpec spec) override {
    // Strings are built once at load time; the runtime never writes them.
    const bool writable = !spec.load_time_only && ref.type != ParamType::kString;
    std::string def = default_text(ref);
    rows.push_back({"`" + cell(name) + "`", std::string(rt::to_string(ref.type)), cell(spec.unit),
                    cell(range_text(ref.type, spec)), def.empty() ? "" : "`" + cell(def) + "`",
                    writable ? "yes" : "no", cell(spec.description)});
  }
};

}  // namespace

std::string param_table(rt::Block& block) {
  RowCollector c;
  block.visit_params(c);
  if (c.rows.empty()) {
    return "No parameters.\n";
  }
  std::string out =
      "| parameter | type | unit | range | default | run-time writable | description |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const Row& r : c.rows) {
    out += "| " + r.name + " | " + r.type + " | " + r.unit + " | " + r.range + " | " +
           r.default_value + " | " + r.writable + " | " + r.description + " |\n";
  }
  return out;
}

}  // namespace edm::paramdoc
