// Machine-config reader for the HMI: machine.axes and conditions only. See machine_config.hpp.

#include "edm/machining/machine_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

namespace edm::machining {

MachineConfigError::MachineConfigError(std::vector<std::string> messages)
    : std::runtime_error(messages.empty() ? std::string("invalid machine config") : messages[0]),
      messages_(std::move(messages)) {}

namespace {

struct Located {
  int line{0};
  int col{0};
  std::string text;
};

/// Strict reader of yaml-cpp nodes that collects located messages (like the runtime's).
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  void error(const YAML::Node& at, const std::string& path, const std::string& message) {
    const YAML::Mark m = at.Mark();
    add(m.line, m.column, path.empty() ? message : path + ": " + message);
  }
  void add(int line0, int col0, const std::string& message) {
    const int line = line0 < 0 ? 0 : line0 + 1;
    const int col = col0 < 0 ? 0 : col0 + 1;
    errors_.push_back(
        {line, col,
         file_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + message});
  }

  static std::string describe(const YAML::Node& n) {
    switch (n.Type()) {
      case YAML::NodeType::Map:
        return "a map";
      case YAML::NodeType::Sequence:
        return "a list";
      case YAML::NodeType::Scalar:
        return "'" + n.Scalar().substr(0, 40) + "'";
      default:
        return "nothing (null)";
    }
  }

  /// Checks a map's keys (scalar, unique, allowed); returns the first node of each key.
  std::optional<std::vector<std::pair<std::string, YAML::Node>>> map(
      const YAML::Node& n, const std::string& path, std::initializer_list<const char*> allowed) {
    if (!n.IsMap()) {
      error(n, path, "expected a map, got " + describe(n));
      return std::nullopt;
    }
    std::vector<std::pair<std::string, YAML::Node>> out;
    for (const auto& kv : n) {
      const YAML::Node& key = kv.first;
      if (!key.IsScalar()) {
        error(key, path, "keys must be plain strings, got " + describe(key));
        continue;
      }
      const std::string& k = key.Scalar();
      auto same = [&](const auto& p) { return p.first == k; };
      if (std::find_if(out.begin(), out.end(), same) != out.end()) {
        error(key, path, "duplicate key '" + k + "'");
        continue;
      }
      if (allowed.size() != 0 && std::find_if(allowed.begin(), allowed.end(), [&](const char* a) {
                                   return k == a;
                                 }) == allowed.end()) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        error(key, path, "unknown key '" + k + "' (allowed keys: " + list + ")");
        continue;
      }
      out.emplace_back(k, kv.second);
    }
    return out;
  }

  std::optional<std::string> string(const YAML::Node& n, const std::string& path) {
    if (!n.IsScalar() || n.Scalar().empty()) {
      error(n, path, "expected a string, got " + describe(n));
      return std::nullopt;
    }
    return n.Scalar();
  }

  std::optional<double> real(const YAML::Node& n, const std::string& path) {
    if (n.IsScalar() && n.Tag() != "!") {  // "!" marks a quoted scalar: a string
      const std::string& s = n.Scalar();
      const char* b = s.data();
      if (!s.empty() && *b == '+') ++b;
      double v = 0.0;
      const auto [end, ec] = std::from_chars(b, s.data() + s.size(), v);
      if (ec == std::errc{} && end == s.data() + s.size() && std::isfinite(v) &&
          s.find_first_of("iInN") == std::string::npos) {
        return v;
      }
    }
    error(n, path, "expected a number, got " + describe(n));
    return std::nullopt;
  }

  std::optional<long long> integer(const YAML::Node& n, const std::string& path, long long min,
                                   long long max) {
    if (n.IsScalar() && n.Tag() != "!") {
      const std::string& s = n.Scalar();
      long long v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec == std::errc{} && end == s.data() + s.size()) {
        if (v < min || v > max) {
          error(n, path,
                "must be in " + std::to_string(min) + ".." + std::to_string(max) + " (got " + s +
                    ")");
          return std::nullopt;
        }
        return v;
      }
    }
    error(n, path, "expected an integer, got " + describe(n));
    return std::nullopt;
  }

  std::optional<std::string> choice(const YAML::Node& n, const std::string& path,
                                    std::initializer_list<const char*> choices) {
    auto s = string(n, path);
    if (!s) return std::nullopt;
    std::string list;
    for (const char* c : choices) {
      if (*s == c) return s;
      list += (list.empty() ? "" : ", ") + std::string(c);
    }
    error(n, path, "must be one of " + list + " (got '" + s->substr(0, 40) + "')");
    return std::nullopt;
  }

  void throw_if_any() {
    if (errors_.empty()) return;
    std::stable_sort(errors_.begin(), errors_.end(), [](const Located& a, const Located& b) {
      return a.line != b.line ? a.line < b.line : a.col < b.col;
    });
    std::vector<std::string> messages;
    messages.reserve(errors_.size());
    for (Located& e : errors_) messages.push_back(std::move(e.text));
    throw MachineConfigError(std::move(messages));
  }

 private:
  std::string file_;
  std::vector<Located> errors_;
};

using Fields = std::vector<std::pair<std::string, YAML::Node>>;

const YAML::Node* find(const Fields& f, const char* key) {
  for (const auto& [k, v] : f)
    if (k == key) return &v;
  return nullptr;
}

void positive(Reader& r, const Fields& f, const std::string& path, const char* key, double& out) {
  if (const YAML::Node* n = find(f, key)) {
    if (auto x = r.real(*n, path + "." + key)) {
      if (*x <= 0.0) {
        r.error(*n, path + "." + key, "must be > 0 (got " + n->Scalar() + ")");
      } else {
        out = *x;
      }
    }
  }
}

void parse_axis(Reader& r, const YAML::Node& n, const std::string& path, MachineTables& out) {
  auto m = r.map(n, path, {"name", "min_mm", "max_mm", "v_max_mm_s", "a_max_mm_s2"});
  if (!m) return;
  AxisLimits a;
  bool ok = true;
  const YAML::Node* name = find(*m, "name");
  if (name == nullptr) {
    r.error(n, path, "missing required key 'name'");
    ok = false;
  } else if (auto s = r.choice(*name, path + ".name", {"X", "Y", "Z"})) {
    a.name = (*s)[0];
    if (out.axis(a.name) != nullptr) {
      r.error(*name, path + ".name", "duplicate axis '" + *s + "'");
      ok = false;
    }
  } else {
    ok = false;
  }
  std::optional<double> min_mm;
  std::optional<double> max_mm;
  for (const char* key : {"min_mm", "max_mm"}) {
    const YAML::Node* v = find(*m, key);
    if (v == nullptr) {
      r.error(n, path, std::string("missing required key '") + key + "'");
      continue;
    }
    (key[1] == 'i' ? min_mm : max_mm) = r.real(*v, path + "." + key);
  }
  if (min_mm && max_mm && *max_mm <= *min_mm) {
    const YAML::Node* v = find(*m, "max_mm");
    r.error(*v, path + ".max_mm",
            "must be > min_mm (got max_mm " + v->Scalar() + " <= min_mm " +
                find(*m, "min_mm")->Scalar() + ")");
    ok = false;
  }
  if (!min_mm || !max_mm) ok = false;
  a.min_mm = min_mm.value_or(0.0);
  a.max_mm = max_mm.value_or(0.0);
  positive(r, *m, path, "v_max_mm_s", a.v_max_mm_s);
  positive(r, *m, path, "a_max_mm_s2", a.a_max_mm_s2);
  if (ok) out.axes.push_back(a);
}

void parse_condition(Reader& r, const YAML::Node& n, const std::string& path, MachineTables& out) {
  auto m = r.map(n, path,
                 {"E", "name", "polarity", "open_voltage_v", "peak_current_a", "on_time_us",
                  "off_time_us", "tdr_us", "servo_ref_v", "wear_ratio"});
  if (!m) return;
  Condition c;
  const YAML::Node* e = find(*m, "E");
  if (e == nullptr) {
    r.error(n, path, "missing required key 'E'");
  } else if (auto v = r.integer(*e, path + ".E", 1, INT_MAX)) {
    c.e = static_cast<int>(*v);
    if (out.condition(c.e) != nullptr) {
      r.error(*e, path + ".E", "duplicate condition E" + std::to_string(c.e));
      c.e = 0;
    }
  }
  if (const YAML::Node* v = find(*m, "name")) c.name = r.string(*v, path + ".name").value_or("");
  if (const YAML::Node* v = find(*m, "polarity")) {
    if (auto s = r.choice(*v, path + ".polarity", {"negative", "positive"})) {
      c.polarity = *s == "positive" ? Polarity::kPositive : Polarity::kNegative;
    }
  }
  positive(r, *m, path, "open_voltage_v", c.open_voltage_v);
  positive(r, *m, path, "peak_current_a", c.peak_current_a);
  positive(r, *m, path, "on_time_us", c.on_time_us);
  positive(r, *m, path, "off_time_us", c.off_time_us);
  positive(r, *m, path, "tdr_us", c.tdr_us);
  positive(r, *m, path, "servo_ref_v", c.servo_ref_v);
  if (const YAML::Node* v = find(*m, "wear_ratio")) {
    if (auto x = r.real(*v, path + ".wear_ratio")) {
      if (*x < 0.0 || *x > 10.0) {
        r.error(*v, path + ".wear_ratio", "must be in 0..10 (got " + v->Scalar() + ")");
      } else {
        c.wear_ratio = *x;
      }
    }
  }
  if (c.e >= 1) out.conditions.push_back(std::move(c));
}

template <class F>
void each(Reader& r, const YAML::Node& list, const std::string& path, F&& f) {
  if (!list.IsSequence()) {
    r.error(list, path, "expected a list, got " + Reader::describe(list));
    return;
  }
  std::size_t i = 0;
  for (const auto& item : list) f(item, path + "[" + std::to_string(i++) + "]");
}

}  // namespace

MachineTables parse_machine_tables(std::string_view yaml_text, const std::string& file) {
  Reader r(file);
  MachineTables out;
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    r.add(e.mark.line, e.mark.column, "YAML syntax error: " + e.msg);
    r.throw_if_any();
  }
  if (!root.IsMap()) {
    r.add(0, 0,
          "the top level must be a map (version, machine, conditions, ...), got " +
              Reader::describe(root));
    r.throw_if_any();
  }
  // Only these two sections are checked; the others are the runtime loader's.
  auto top = r.map(root, "", {});
  if (top) {
    if (const YAML::Node* v = find(*top, "version")) {
      if (!(v->IsScalar() && v->Scalar() == "1")) {
        r.error(*v, "version", "unsupported version " + Reader::describe(*v) + " (expected 1)");
      }
    }
    const YAML::Node* machine = find(*top, "machine");
    if (machine == nullptr) {
      r.add(0, 0, "missing required key 'machine'");
    } else if (!machine->IsMap()) {
      r.error(*machine, "machine", "expected a map, got " + Reader::describe(*machine));
    } else if (const YAML::Node axes = (*machine)["axes"]; axes.IsDefined()) {
      each(r, axes, "machine.axes", [&](const YAML::Node& item, const std::string& path) {
        parse_axis(r, item, path, out);
      });
    }
    if (const YAML::Node* conditions = find(*top, "conditions")) {
      each(r, *conditions, "conditions", [&](const YAML::Node& item, const std::string& path) {
        parse_condition(r, item, path, out);
      });
    }
  }
  r.throw_if_any();
  return out;
}

MachineTables read_machine_tables(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw MachineConfigError(
        {path + ": cannot open: " + std::string(err != 0 ? std::strerror(err) : "error")});
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_machine_tables(ss.str(), path);
}

}  // namespace edm::machining
