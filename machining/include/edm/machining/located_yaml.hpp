#pragma once
// Strict, located reading of yaml-cpp nodes, shared by every reader of a machine config (the
// runtime's config parser and machining's machine-table reader), so a value is judged and
// reported the same way wherever it is read. Every check reports "path: problem" at the offending
// key or value and returns nullopt so the caller can carry on with the next key (errors are
// collected in a DiagnosticSink, not thrown).
// Needs yaml-cpp: include it only from code that links yaml-cpp (machining does, privately; the
// HMI does not include this header).
// Non-RT (allocates, uses yaml-cpp); thread-compatible (one Reader per parse).

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "edm/machining/diagnostics.hpp"

namespace edm::machining::yaml {

/// What a scalar's text means under the YAML 1.2 core schema, restricted to what configs use:
/// decimal integers, decimal reals, lower-case true/false.
enum class ScalarKind : std::uint8_t { kNull, kBool, kInt, kReal, kNonFinite, kString };

/// Classifies the text of a plain (unquoted) scalar.
ScalarKind classify_plain(std::string_view text) noexcept;

/// Text for a message: in single quotes, control bytes as '?', cut after 40 characters.
std::string quote(std::string_view text);

/// [A-Za-z_][A-Za-z0-9_]*
bool is_identifier(std::string_view s) noexcept;

/// min_parts..max_parts identifiers joined by '.', e.g. "gap.lp.out".
bool is_dotted_name(std::string_view s, int min_parts, int max_parts) noexcept;

/// A node with where it is and how messages name it ("tasks[0].interval").
struct Value {
  YAML::Node node;
  SourceLoc loc;
  std::string path;
};

/// One `key: value` of a checked map.
struct Field {
  std::string key;
  SourceLoc key_loc;
  Value value;
};

/// A map whose keys were checked: scalars, unique, and (when a key set was given) known.
struct MapView {
  Value self;
  std::vector<Field> fields;           // file order, first occurrence of each key only
  std::vector<std::string> suggested;  // keys offered as "did you mean" for unknown keys

  [[nodiscard]] const Field* find(std::string_view key) const noexcept;
};

class Reader {
 public:
  Reader(std::string file, DiagnosticSink& sink) : file_(std::move(file)), sink_(sink) {}

  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  /// 1-based location of a mark; line 0 when yaml-cpp has none.
  [[nodiscard]] SourceLoc loc(const YAML::Mark& mark) const;
  [[nodiscard]] SourceLoc loc(const YAML::Node& node) const { return loc(node.Mark()); }

  /// Reports "path: message" at loc (just "message" for the top level, whose path is empty).
  void error(const Value& at, const std::string& message);
  void error(const SourceLoc& loc, const std::string& path, const std::string& message);

  /// The node as a map; reports wrong kinds, non-scalar keys, duplicate keys, and keys outside
  /// `allowed` (an empty list allows any key).
  std::optional<MapView> map(const Value& v, std::initializer_list<std::string_view> allowed,
                             std::string_view duplicate_note = {});
  /// The node as a list of elements (paths "path[i]").
  std::optional<std::vector<Value>> list(const Value& v);
  /// Reports "path: missing required key 'key'" at the map when the key is absent (unless an
  /// unknown key was already reported as its likely misspelling).
  const Field* require(const MapView& m, std::string_view key);

  /// True if the node is a scalar without an unsupported tag; else reports "expected <what>".
  bool scalar(const Value& v, const char* expected);

  /// Scalar readers: nullopt after reporting a wrong kind, type or range.
  std::optional<std::string> string(const Value& v, bool allow_empty = false);
  std::optional<std::int64_t> integer(const Value& v, std::int64_t min, std::int64_t max);
  std::optional<double> real(const Value& v);
  /// One of `choices` (quoted or plain), e.g. "skip"/"asap".
  std::optional<std::string> choice(const Value& v,
                                    std::initializer_list<std::string_view> choices);

  /// True if the scalar was written quoted (or tagged !!str): a string, whatever its text.
  [[nodiscard]] static bool is_quoted(const YAML::Node& node);
  /// "a map", "a list", "nothing (null)" or the scalar's text in quotes.
  [[nodiscard]] static std::string describe(const YAML::Node& node);

 private:
  std::string file_;
  DiagnosticSink& sink_;
};

/// Child path: "a" + "b" → "a.b"; "" + "b" → "b".
std::string join_path(const std::string& parent, std::string_view key);

}  // namespace edm::machining::yaml
