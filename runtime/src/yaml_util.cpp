#include "yaml_util.hpp"

namespace edm::rt::yaml_util {

std::optional<Duration> Reader::duration(const Value& v) {
  if (!scalar(v, "a duration")) {
    return std::nullopt;
  }
  const std::string& text = v.node.Scalar();
  if (!is_quoted(v.node)) {
    const ScalarKind kind = classify_plain(text);
    if (kind == ScalarKind::kInt || kind == ScalarKind::kReal) {
      error(v,
            "duration needs a unit, e.g. 1ms (got " + quote(text) + "; units: ns, us, ms, s, min)");
      return std::nullopt;
    }
  }
  if (!text.empty() && text[0] == '-') {
    error(v, "must not be negative (got " + quote(text) + ")");
    return std::nullopt;
  }
  DurationParse parsed = parse_duration(text);
  if (!parsed.value) {
    error(v, parsed.error);
    return std::nullopt;
  }
  return parsed.value;
}

}  // namespace edm::rt::yaml_util
