// Config parser: YAML → Config structs, checking structure, keys, types, ranges and the
// cross-references between sections (task ↔ program). Block types, parameters and wire endpoints
// are the builder's job. All problems are collected and thrown together, sorted by position.

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <system_error>
#include <unordered_map>
#include <unordered_set>

#include "config_parser_impl.hpp"
#include "edm/machining/bounded_read.hpp"
#include "edm/machining/machine_sections.hpp"

namespace edm::rt {

namespace config_detail {

std::optional<Value> Parser::root_map(const YAML::Node& root, const char* empty,
                                      const char* not_map) {
  Value top{root, r_.loc(root), ""};
  if (top.loc.line == 0) {
    top.loc = {r_.file(), 1, 1};
  }
  if (root.IsNull()) {
    r_.error(top, empty);
    return std::nullopt;
  }
  if (!root.IsMap()) {
    r_.error(top, not_map + Reader::describe(root));
    return std::nullopt;
  }
  return top;
}

void Parser::parse_document(const YAML::Node& root, Config& cfg) {
  const std::optional<Value> top =
      root_map(root, "the file is empty (expected a map with version, machine, tasks and programs)",
               "the top level must be a map (version, machine, tasks, programs, ...), got ");
  if (!top) {
    return;
  }
  // `mqtt` is read by the telemetry library (telemetry/, docs/mqtt.md), `modbus_server` by the
  // modbus library (modbus/, docs/modbus.md); only their places are kept.
  auto m = r_.map(*top, {"version", "machine", "conditions", "tasks", "programs", "trace", "bridge",
                         "retain", "mqtt", "modbus_server"});
  if (const Field* f = r_.require(*m, "version")) {
    auto v = r_.integer(f->value, 0, INT64_MAX);
    if (!v) {
      return;  // the rest may follow another schema
    }
    if (*v != 1) {
      r_.error(f->value,
               "unsupported version " + f->value.node.Scalar() + " (this edmplc reads version 1)");
      return;
    }
    cfg.version = 1;
  }
  if (const Field* f = r_.require(*m, "machine")) {
    parse_machine(f->value, cfg.machine);
  }
  if (const Field* f = m->find("conditions")) {
    cfg.conditions = machining::read_conditions(r_, f->value);
  }
  task_names_complete_ = task_programs_complete_ = false;
  if (const Field* f = r_.require(*m, "tasks")) {
    if (auto items = r_.list(f->value)) {
      task_names_complete_ = task_programs_complete_ = true;
      if (items->empty()) {
        r_.error(f->value, "must list at least one task");
      }
      parse_named(
          *items, cfg.tasks, [this](const Value& v, TaskSpec& t) { parse_task(v, t); }, "task");
    }
  }
  program_names_complete_ = false;
  if (const Field* f = r_.require(*m, "programs")) {
    if (auto items = r_.list(f->value)) {
      program_names_complete_ = true;
      if (items->empty()) {
        r_.error(f->value, "must list at least one program");
      }
      parse_named(
          *items, cfg.programs, [this](const Value& v, ProgramSpec& p) { parse_program(v, p); },
          "program");
    }
  }
  if (const Field* f = m->find("trace")) {
    parse_trace(f->value, cfg.trace);
  }
  if (const Field* f = m->find("bridge")) {
    parse_bridge(f->value, cfg.bridge);
  }
  if (const Field* f = m->find("retain")) {
    parse_retain(f->value, cfg.retain);
  }
  if (const Field* f = m->find("mqtt")) {
    cfg.mqtt_loc = f->key_loc;
  }
  if (const Field* f = m->find("modbus_server")) {
    cfg.modbus_server_loc = f->key_loc;
  }
  cross_check(cfg);
}

void Parser::cross_check(const Config& cfg) {
  if (cfg.machine.io.task && task_names_complete_) {
    const NameRef& ref = *cfg.machine.io.task;
    const bool found = std::any_of(cfg.tasks.begin(), cfg.tasks.end(),
                                   [&](const TaskSpec& t) { return t.name == ref.name; });
    if (!found) {
      r_.error(ref.loc, "machine.io.task", "unknown task '" + ref.name + "'");
    }
  }
  std::unordered_set<std::string> programs;
  for (const ProgramSpec& p : cfg.programs) {
    programs.insert(p.name);
  }
  // program name → the task that runs it and where it was listed
  std::unordered_map<std::string, std::pair<const TaskSpec*, SourceLoc>> owner;
  for (const TaskSpec& t : cfg.tasks) {
    for (const NameRef& ref : t.programs) {
      if (programs.count(ref.name) == 0) {
        if (program_names_complete_) {
          r_.error(ref.loc, "task '" + t.name + "'",
                   "unknown program " + yaml_util::quote(ref.name));
        }
        continue;
      }
      const auto [it, inserted] = owner.emplace(ref.name, std::make_pair(&t, ref.loc));
      if (!inserted) {
        r_.error(ref.loc, "task '" + t.name + "'",
                 "program '" + ref.name + "' is already assigned to task '" +
                     it->second.first->name + "' (line " + line_of(it->second.second) +
                     "); a program instance runs in exactly one task");
      }
    }
  }
  if (task_programs_complete_ && task_names_complete_) {
    for (const ProgramSpec& p : cfg.programs) {
      if (!p.name.empty() && owner.count(p.name) == 0) {
        r_.error(p.name_loc, "program '" + p.name + "'", "not assigned to any task");
      }
    }
  }
}

namespace {

/// Sees where a document starts and ignores everything else.
class DocumentProbe : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

  YAML::Mark start;
};

/// Where a second document starts, if there is one. Not YAML::LoadAll: yaml-cpp 0.7 loops
/// forever (allocating) on a stray top-level ',' because each "document" consumes nothing.
std::optional<YAML::Mark> second_document_mark(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentProbe probe;
  if (!parser.HandleNextDocument(probe) || !parser.HandleNextDocument(probe)) {
    return std::nullopt;
  }
  return probe.start;
}

// Past this, more messages only bury the first ones, which are usually the cause.
constexpr std::size_t kMaxDiagnostics = 100;
// A config is a few KiB; anything this large is the wrong file.
constexpr std::size_t kMaxConfigFileBytes = machining::kMaxConfigBytes;

}  // namespace

std::optional<YAML::Node> load_document(const std::string& text, const Reader& r,
                                        DiagnosticSink& sink) {
  const std::string& path = r.file();
  std::optional<YAML::Node> root;
  try {
    root = YAML::Load(text);
    if (const auto second = second_document_mark(text)) {
      const SourceLoc at = r.loc(*second);
      sink.error(at.line != 0 ? at : SourceLoc{path, 1, 1},
                 "unexpected content after the first YAML document (one document per file)");
    }
  } catch (const YAML::DeepRecursion& e) {
    sink.error(r.loc(e.mark), "YAML nesting is too deep");
  } catch (const YAML::Exception& e) {
    sink.error(r.loc(e.mark), "YAML syntax error: " + e.msg);
  }
  return root;
}

}  // namespace config_detail

using config_detail::kMaxConfigFileBytes;
using config_detail::kMaxDiagnostics;

Config parse_config_text(const std::string& text, const std::string& path) {
  if (text.size() > kMaxConfigFileBytes) {  // the same bound for text that came another way
    throw ConfigError({{{path, 1, 1},
                        "config is " + std::to_string(text.size()) + " bytes; the limit is " +
                            std::to_string(kMaxConfigFileBytes >> 20) + " MiB"}});
  }
  DiagnosticSink sink;
  Config cfg;
  cfg.path = path;
  config_detail::IncludeState inc;
  inc.stack.push_back({config_detail::canonical_path(path), path});
  inc.bytes = text.size();
  inc.included = &cfg.includes;
  config_detail::Parser parser(path, sink, inc);
  config_detail::Reader reader(path, sink);
  if (const auto root = config_detail::load_document(text, reader, sink)) {
    parser.parse_document(*root, cfg);
  }
  if (sink.empty()) {
    return cfg;
  }
  std::vector<Diagnostic> diags = with_include_notes(cfg, sink.diagnostics());
  if (diags.size() > kMaxDiagnostics) {
    const std::size_t more = diags.size() - kMaxDiagnostics;
    SourceLoc at = diags[kMaxDiagnostics].loc;
    diags.resize(kMaxDiagnostics);
    diags.push_back({at, std::to_string(more) + " more errors not shown"});
  }
  throw ConfigError(std::move(diags));
}

Config parse_config_file(const std::string& path) {
  // Bounded and type-checked before reading: a FIFO, a device or a huge file is refused at 1:1.
  machining::BoundedRead file = machining::read_bounded_file(path, kMaxConfigFileBytes, "config");
  if (!file.ok()) {
    throw ConfigError({{{path, 1, 1}, file.problem}});
  }
  return parse_config_text(file.text, path);
}

machining::MachineTables to_machine_tables(const Config& cfg) {
  return machining::make_tables(cfg.machine.axes, cfg.conditions, cfg.machine.kind);
}

}  // namespace edm::rt
