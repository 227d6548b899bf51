#pragma once
// Explicit registries of block and driver types by name (no static-init self-registration).
// Thread-safety: fill once at start-up (non-RT), then read-only.

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace edm::rt {

template <class Base>
class TypeRegistry {
 public:
  using Factory = std::unique_ptr<Base> (*)();

  struct Entry {
    Factory factory;
    std::string summary;  // one line for listings and docs
  };

  /// Registers type T under name; a second registration of the same name replaces nothing and
  /// returns false (the caller's list has a duplicate).
  template <class T>
  bool add(std::string name, std::string summary = {}) {
    return entries_
        .emplace(std::move(name),
                 Entry{[]() -> std::unique_ptr<Base> { return std::make_unique<T>(); },
                       std::move(summary)})
        .second;
  }
  /// A new instance, or nullptr for an unknown name.
  [[nodiscard]] std::unique_ptr<Base> create(std::string_view name) const {
    auto it = entries_.find(std::string(name));
    return it == entries_.end() ? nullptr : it->second.factory();
  }
  [[nodiscard]] bool contains(std::string_view name) const {
    return entries_.find(std::string(name)) != entries_.end();
  }
  [[nodiscard]] std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [name, e] : entries_) {
      out.push_back(name);
    }
    return out;
  }
  [[nodiscard]] const std::map<std::string, Entry, std::less<>>& entries() const {
    return entries_;
  }

 private:
  std::map<std::string, Entry, std::less<>> entries_;
};

class Block;
class IoDriver;
using BlockRegistry = TypeRegistry<Block>;
using DriverRegistry = TypeRegistry<IoDriver>;

}  // namespace edm::rt
