#pragma once
// Reads the two sections of a machine config (DESIGN §8) that the HMI needs to check a part
// program offline: `machine.axes` (soft limits) and `conditions` (the E-number table), through the
// same section reader as the runtime's loader (machine_sections.hpp), so keys, types, ranges,
// defaults and messages are the runtime's; the other sections (tasks, programs, ...) are the
// runtime's business and are not looked at.
//
// Non-RT (allocates, reads files). Thread-safety: the functions are reentrant.

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "edm/machining/machine_tables.hpp"

namespace edm::machining {

/// Every problem found in a machine config, each as "file:line:col: message" in file order;
/// what() is the first one.
class MachineConfigError : public std::runtime_error {
 public:
  explicit MachineConfigError(std::vector<std::string> messages);
  [[nodiscard]] const std::vector<std::string>& messages() const noexcept { return messages_; }

 private:
  std::vector<std::string> messages_;
};

/// Reads `path`. Throws MachineConfigError (unreadable file, YAML syntax, unknown or duplicate
/// keys in an axis or condition, wrong types, out-of-range values, duplicate axes or E numbers).
MachineTables read_machine_tables(const std::string& path);

/// The same from text; `file` names it in messages.
MachineTables parse_machine_tables(std::string_view yaml_text, const std::string& file);

}  // namespace edm::machining
