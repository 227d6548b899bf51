#pragma once
// Private helpers of the config parser: machining's located YAML reader (shared with the HMI's
// reader of machine configs, edm/machining/located_yaml.hpp) plus what only the runtime reads,
// durations. Non-RT (allocates, uses yaml-cpp); thread-compatible (one Reader per parse).

#include <optional>
#include <string>

#include "edm/machining/located_yaml.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt::yaml_util {

using machining::yaml::classify_plain;
using machining::yaml::Field;
using machining::yaml::is_dotted_name;
using machining::yaml::is_identifier;
using machining::yaml::join_path;
using machining::yaml::MapView;
using machining::yaml::quote;
using machining::yaml::ScalarKind;
using machining::yaml::Value;

class Reader : public machining::yaml::Reader {
 public:
  using machining::yaml::Reader::Reader;

  /// A duration with a unit ("250us", "1ms"); nullopt after reporting a bad one.
  std::optional<Duration> duration(const Value& v);
};

}  // namespace edm::rt::yaml_util
