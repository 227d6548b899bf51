#include "edm/runtime/config_section.hpp"

#include "edm/machining/bounded_read.hpp"
#include "edm/runtime/diagnostics.hpp"

namespace edm::rt {

std::string read_config_text(const Config& cfg) {
  machining::BoundedRead file =
      machining::read_bounded_file(cfg.path, machining::kMaxConfigBytes, "config");
  if (!file.ok()) {
    throw ConfigError({{{cfg.path, 1, 1}, file.problem}});
  }
  return std::move(file.text);
}

std::optional<machining::yaml::Value> config_section(const std::string& text,
                                                     const std::string& path,
                                                     const std::string& key) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError({{{path, e.mark.line + 1, e.mark.column + 1}, "YAML: " + e.msg}});
  }
  if (!root.IsMap() || !root[key]) {
    return std::nullopt;
  }
  const YAML::Node node = root[key];
  machining::DiagnosticSink unused;  // loc() reports nothing
  const machining::yaml::Reader locator(path, unused);
  return machining::yaml::Value{node, locator.loc(node), key};
}

}  // namespace edm::rt
