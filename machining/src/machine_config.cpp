// Machine-config reader for the HMI: machine.axes and conditions only, through the same section
// reader as the runtime's config parser (machine_sections.hpp). See machine_config.hpp.

#include "edm/machining/machine_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "edm/machining/bounded_read.hpp"
#include "edm/machining/diagnostics.hpp"
#include "edm/machining/located_yaml.hpp"
#include "edm/machining/machine_sections.hpp"

namespace edm::machining {

MachineConfigError::MachineConfigError(std::vector<std::string> messages)
    : std::runtime_error(messages.empty() ? std::string("invalid machine config") : messages[0]),
      messages_(std::move(messages)) {}

namespace {

[[noreturn]] void throw_all(const DiagnosticSink& sink) {
  std::vector<std::string> messages;
  for (const Diagnostic& d : sink.sorted()) messages.push_back(d.str());
  throw MachineConfigError(std::move(messages));
}

}  // namespace

MachineTables parse_machine_tables(std::string_view yaml_text, const std::string& file) {
  DiagnosticSink sink;
  yaml::Reader r(file, sink);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    sink.error(r.loc(e.mark), "YAML syntax error: " + e.msg);
    throw_all(sink);
  }
  yaml::Value top{root, r.loc(root), ""};
  if (top.loc.line == 0) top.loc = {file, 1, 1};
  if (!root.IsMap()) {
    r.error(top, "the top level must be a map (version, machine, conditions, ...), got " +
                     yaml::Reader::describe(root));
    throw_all(sink);
  }
  // Only these sections are read; the others (tasks, programs, ...) are the runtime loader's.
  std::vector<LocatedAxis> axes;
  std::vector<LocatedCondition> conditions;
  MachineKind kind = MachineKind::kDrill;
  if (auto m = r.map(top, {})) {
    if (const yaml::Field* v = m->find("version")) {
      if (!(v->value.node.IsScalar() && v->value.node.Scalar() == "1")) {
        r.error(v->value,
                "unsupported version " + yaml::Reader::describe(v->value.node) + " (expected 1)");
      }
    }
    if (const yaml::Field* machine = r.require(*m, "machine")) {
      // machine.name and machine.io are the runtime's; only the axes are read here.
      if (auto mm = r.map(machine->value, {})) {
        if (const yaml::Field* f = mm->find("axes")) axes = read_axes(r, f->value);
        if (const yaml::Field* f = mm->find("kind")) kind = read_machine_kind(r, f->value);
      }
    }
    if (const yaml::Field* f = m->find("conditions")) conditions = read_conditions(r, f->value);
  }
  if (!sink.empty()) throw_all(sink);
  return make_tables(axes, conditions, kind);
}

MachineTables read_machine_tables(const std::string& path) {
  const BoundedRead file = read_bounded_file(path, kMaxConfigBytes, "config");
  if (!file.ok()) throw MachineConfigError({file.error});
  return parse_machine_tables(file.text, path);
}

}  // namespace edm::machining
