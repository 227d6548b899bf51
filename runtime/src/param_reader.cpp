#include "param_reader.hpp"

#include <charconv>
#include <cmath>
#include <set>

namespace edm::rt {

namespace {

class SettingsReader final : public ParamVisitor {
 public:
  SettingsReader(const std::vector<ParamSetting>& settings, std::string_view what,
                 DiagnosticSink& diag)
      : settings_(settings), what_(what), diag_(diag) {}

  std::set<std::string> used;
  std::vector<std::string> names;

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamInfo /*info*/) override {
    names.emplace_back(name);
    for (const ParamSetting& s : settings_) {
      if (s.key == name) {
        used.insert(s.key);
        convert(s, ref);
      }
    }
  }

 private:
  void bad(const ParamSetting& s, std::string_view type, std::string_view hint) {
    diag_.error(s.value_loc, std::string(what_) + ": parameter '" + s.key + "' is " +
                                 std::string(type) + ", got '" + s.value + "'" + std::string(hint));
  }

  void convert(const ParamSetting& s, ParamRef ref) {
    const std::string& t = s.value;
    const char* b = t.data();
    const char* e = t.data() + t.size();
    switch (ref.type) {
      case ParamType::kBool:
        if (!s.quoted && (t == "true" || t == "false")) {
          *static_cast<bool*>(ref.field) = t == "true";
        } else {
          bad(s, "BOOL", " (use true or false)");
        }
        return;
      case ParamType::kInt: {
        std::int64_t v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (s.quoted || ec != std::errc{} || p != e || t.empty()) {
          bad(s, "LINT", " (a whole number)");
        } else {
          *static_cast<std::int64_t*>(ref.field) = v;
        }
        return;
      }
      case ParamType::kReal: {
        double v = 0.0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (s.quoted || ec != std::errc{} || p != e || t.empty() || !std::isfinite(v)) {
          bad(s, "LREAL", " (a finite number)");
        } else {
          *static_cast<double*>(ref.field) = v;
        }
        return;
      }
      case ParamType::kDuration: {
        DurationParse d = parse_duration(t);
        if (!d.value) {
          diag_.error(s.value_loc, std::string(what_) + ": parameter '" + s.key + "': " + d.error);
        } else {
          *static_cast<Duration*>(ref.field) = *d.value;
        }
        return;
      }
      case ParamType::kString: *static_cast<std::string*>(ref.field) = t; return;
    }
  }

  const std::vector<ParamSetting>& settings_;
  std::string_view what_;
  DiagnosticSink& diag_;
};

}  // namespace

std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& s : names) {
    out += (out.empty() ? "" : ", ") + s;
  }
  return out.empty() ? "none" : out;
}

void read_params(Block& block, const std::vector<ParamSetting>& settings, std::string_view what,
                 DiagnosticSink& diag) {
  SettingsReader r(settings, what, diag);
  block.visit_params(r);
  for (const ParamSetting& s : settings) {
    if (r.used.count(s.key) == 0) {
      diag.error(s.key_loc, std::string(what) + ": unknown parameter '" + s.key +
                                "' (parameters: " + join_names(r.names) + ")");
    }
  }
}

void report_param_errors(const std::vector<ParamError>& errs,
                         const std::vector<ParamSetting>& settings, std::string_view what,
                         const SourceLoc& fallback, DiagnosticSink& diag) {
  for (const ParamError& e : errs) {
    SourceLoc loc = fallback;
    for (const ParamSetting& s : settings) {
      if (!e.field.empty() && s.key == e.field) {
        loc = s.value_loc;
      }
    }
    diag.error(loc, std::string(what) + ": " + (e.field.empty() ? "" : e.field + " ") + e.message);
  }
}

void report_validation(const Block& block, const std::vector<ParamSetting>& settings,
                       std::string_view what, const SourceLoc& fallback, DiagnosticSink& diag) {
  report_param_errors(block.validate(), settings, what, fallback, diag);
}

}  // namespace edm::rt
