#pragma once
// A top-level section of a config file that the runtime's parser only locates (`mqtt:`,
// `modbus_server:`, see Config) and the library that owns its keys reads itself: the file read
// again and the section found in it, with the same errors for every such library.
// Needs yaml-cpp (it names yaml-cpp's nodes, like edm/machining/located_yaml.hpp): include it
// only from code that links yaml-cpp. Non-RT (allocates, throws); thread-compatible.

#include <optional>
#include <string>

#include "edm/machining/located_yaml.hpp"
#include "edm/runtime/config.hpp"

namespace edm::rt {

/// The text of the file `cfg` was parsed from. Throws ConfigError ("PATH:1:1: problem") when it
/// can no longer be read or has grown past the config bound.
std::string read_config_text(const Config& cfg);

/// Section `key` of the YAML document `text` (named `path` in messages), located, its path
/// `key`; nullopt when the document is not a map or has no such key. Throws ConfigError
/// ("PATH:LINE:COL: YAML: ...") when `text` is not YAML.
std::optional<machining::yaml::Value> config_section(const std::string& text,
                                                     const std::string& path,
                                                     const std::string& key);

}  // namespace edm::rt
