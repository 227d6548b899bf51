#pragma once
// Private to the config parser: the Parser class shared by config_parser.cpp (document, cross
// references, entry points) and config_sections.cpp (one function per section).
// Non-RT; thread-compatible (one Parser per parse).

#include <climits>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "edm/runtime/config.hpp"
#include "yaml_util.hpp"

namespace edm::rt::config_detail {

using yaml_util::Field;
using yaml_util::MapView;
using yaml_util::Reader;
using yaml_util::ScalarKind;
using yaml_util::Value;

constexpr std::int64_t kMaxInt = INT_MAX;
// DESIGN §9: a protocol line is at most 1 MiB; a bigger limit would only let one request hold
// more of the bridge's memory.
constexpr std::int64_t kMaxLineBytes = std::int64_t{1} << 20;

inline std::string line_of(const SourceLoc& loc) { return std::to_string(loc.line); }

class UniqueNames {
 public:
  /// Returns the first location if `name` was seen before.
  const SourceLoc* add(const std::string& name, const SourceLoc& loc) {
    const auto [it, inserted] = first_.emplace(name, loc);
    return inserted ? nullptr : &it->second;
  }
  [[nodiscard]] bool contains(const std::string& name) const { return first_.count(name) != 0; }

 private:
  std::unordered_map<std::string, SourceLoc> first_;
};

/// "file:line:col" of a location, for messages naming another place.
std::string where(const SourceLoc& loc);

/// The path made absolute and canonical as far as it exists (a cycle is the same file reached
/// again, whatever the spelling).
std::string canonical_path(const std::string& path);

/// The one YAML document of `text` (reported at Reader's file when it is not one), or nullopt.
std::optional<YAML::Node> load_document(const std::string& text, const Reader& r,
                                        DiagnosticSink& sink);

/// The fragments of one parse (config_include.cpp): what is being read, to refuse cycles, depth
/// and size, and what was read, for Config::includes.
struct IncludeState {
  struct Frame {
    std::string canonical;  // to recognise a cycle
    std::string file;       // as messages name it
  };
  std::vector<Frame> stack;  // the config file first, then each fragment being read
  std::size_t bytes{0};      // of the config and every fragment read so far
  std::vector<IncludedFile>* included{nullptr};
};

class Parser {
 public:
  Parser(const std::string& path, DiagnosticSink& sink, IncludeState& inc)
      : r_(path, sink), sink_(sink), inc_(inc) {}

  void parse_document(const YAML::Node& root, Config& cfg);

 private:
  // A file's root, located (1:1 when yaml-cpp has no mark) and checked to be a map: nullopt after
  // reporting `empty` for an empty file, or `not_map` + what it is instead.
  std::optional<Value> root_map(const YAML::Node& root, const char* empty, const char* not_map);
  void parse_machine(const Value& v, MachineSpec& out);
  void parse_io(const Value& v, IoSpec& out);
  // config_io.cpp: a driver's pin map and a composite's drivers.
  void parse_io_extras(const MapView& m, IoSpec& out);
  void parse_io_child(const Value& v, IoSpec& out);
  void parse_pin_map(const Value& v, std::vector<PinMapSpec>& out);
  void parse_realtime(const Value& v, RealtimeSpec& out);
  void parse_electrode(const Value& v, ElectrodeSpec& out);
  void parse_condition_edit(const Value& v, std::vector<std::string>& out);
  void parse_safety(const Value& v, MachineSpec& machine);  // config_safety.cpp
  void parse_safety_axis(const Value& v, const MachineSpec& machine, SafetyAxisSpec& out);
  void parse_short_stop(const Value& v, SafetySpec& out);
  std::optional<NameRef> io_pin_name(const Value& v);
  void parse_task(const Value& v, TaskSpec& out);
  void parse_watchdog(const Value& v, WatchdogSpec& out);
  void parse_program(const Value& v, ProgramSpec& out);
  void parse_block(const Value& v, BlockSpec& out);
  void parse_params(const Value& v, std::vector<ParamSetting>& out);
  void parse_params_under(const Value& v, const std::string& prefix, int depth,
                          std::vector<ParamSetting>& out);
  void parse_wires(const Value& v, std::vector<WireSpec>& out);
  // config_include.cpp: `include:` of a program, and a fragment's blocks and wires appended to it
  // (a block name or wire destination the program already has is an error naming both places).
  void parse_include(const Value& v, ProgramSpec& out);
  void include_one(const Value& item, ProgramSpec& out);
  void parse_fragment(const YAML::Node& root, ProgramSpec& out);
  void append_blocks(std::vector<BlockSpec>& blocks, ProgramSpec& out);
  void append_wires(std::vector<WireSpec>& wires, ProgramSpec& out);
  void parse_trace(const Value& v, TraceSpec& out);
  void parse_bridge(const Value& v, BridgeSpec& out);
  void parse_retain(const Value& v, RetainSpec& out);
  std::vector<NameRef> parse_variable_names(const Value& v);
  void cross_check(const Config& cfg);

  // Optional-field helpers: read `key` if present and store it on success.
  std::optional<std::string> identifier(const Value& v, const char* what);
  // The required `name` of a program or block: an identifier other than the reserved "io" (which
  // is still stored, so that references to it don't cascade).
  void program_or_block_name(const MapView& m, const char* what, std::string& name,
                             SourceLoc& name_loc);
  template <class Int>
  void int_in(const MapView& m, std::string_view key, std::int64_t min, std::int64_t max,
              Int& out) {
    if (const Field* f = m.find(key)) {
      if (auto x = r_.integer(f->value, min, max)) {
        out = static_cast<Int>(*x);
      }
    }
  }

  // Parses each list item with parse_one(item, spec) into `out`; a name seen before is an error
  // "duplicate <kind> name 'n'<context> (first at line L)".
  template <class Spec, class ParseOne>
  void parse_named(const std::vector<Value>& items, std::vector<Spec>& out, ParseOne parse_one,
                   const std::string& kind, const std::string& context = {}) {
    UniqueNames names;
    for (const Value& item : items) {
      Spec spec;
      parse_one(item, spec);
      if (!spec.name.empty()) {
        if (const SourceLoc* first = names.add(spec.name, spec.name_loc)) {
          r_.error(spec.name_loc, item.path + ".name",
                   "duplicate " + kind + " name '" + spec.name + "'" + context +
                       " (first at line " + line_of(*first) + ")");
        }
      }
      out.push_back(std::move(spec));
    }
  }

  Reader r_;
  DiagnosticSink& sink_;
  IncludeState& inc_;
  // Cross-reference checks stay quiet when a section could not be read, to avoid cascades.
  bool task_names_complete_{true};
  bool task_programs_complete_{true};
  bool program_names_complete_{true};
};

}  // namespace edm::rt::config_detail
