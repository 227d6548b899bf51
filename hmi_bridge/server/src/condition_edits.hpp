#pragma once
// The operators' edits of the machining conditions (condition.set; docs/protocol.md), retained
// beside the retain file as `<retain>.conditions.json` and applied again when edmplc starts, so
// an edit outlives a restart. The config stays the machine builder's: an edit the config no
// longer allows (the field not in machine.condition_edit, the condition gone, the value out of
// range) is dropped at start with a warning; a file that cannot be read is set aside as
// `….conditions.json.bad` (a warning) and the config's values are used.
//
// Non-RT. Not thread-safe: the bridge's I/O thread only.

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace edm::rt {
class Runtime;
}

namespace edm::bridge {

class ConditionEdits {
 public:
  static constexpr std::size_t kMaxFileBytes = std::size_t{1} << 20;
  static constexpr int kFormat = 1;

  /// `path` empty: in memory only (edits last until edmplc stops).
  explicit ConditionEdits(std::string path) : path_(std::move(path)) {}

  /// Reads the file and applies each edit to `rt` (the config's values where one fails).
  void load_and_apply(rt::Runtime& rt);
  /// condition.set: applies the edit to `rt`; nullopt when done (and written), else why not.
  std::optional<std::string> set(rt::Runtime& rt, int e, const std::string& field, double value);
  [[nodiscard]] bool retained() const noexcept { return !path_.empty(); }
  /// The last write failed (a full disk, a read-only state directory): the edit holds until
  /// edmplc stops.
  [[nodiscard]] bool write_failed() const noexcept { return write_failed_; }

 private:
  bool save();

  std::string path_;
  std::map<std::pair<int, std::string>, double> edits_;  // (E, field) → value
  bool write_failed_{false};
};

}  // namespace edm::bridge
