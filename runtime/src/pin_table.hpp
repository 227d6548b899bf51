#pragma once
// The runtime builder's table of every pin by its full name ("<prefix>.<pin>"): what a wire, a
// trace channel or a variable names is looked up here (runtime_builder.cpp).

#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "edm/runtime/pin.hpp"

namespace edm::rt {

class Task;

struct PinEntry {
  PinRef ref;
  std::string unit;
  Task* owner{nullptr};
};

// Collects a block's pins into a table keyed by "<prefix>.<pin>".
class PinCollector final : public PinVisitor {
 public:
  PinCollector(std::string prefix, Task* owner, std::map<std::string, PinEntry>& table,
               std::vector<std::string>& names)
      : prefix_(std::move(prefix)), owner_(owner), table_(table), names_(names) {}
  std::vector<std::string> duplicates;

 protected:
  void on_pin(std::string_view name, PinRef ref, std::string_view unit) override {
    std::string full = prefix_ + "." + std::string(name);
    names_.emplace_back(name);
    if (!table_.emplace(full, PinEntry{ref, std::string(unit), owner_}).second) {
      duplicates.push_back(full);
    }
  }

 private:
  std::string prefix_;
  Task* owner_;
  std::map<std::string, PinEntry>& table_;
  std::vector<std::string>& names_;
};

}  // namespace edm::rt
