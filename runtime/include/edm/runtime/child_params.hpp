#pragma once
// The parameters of a composite's children as one index space, shared by the two composites
// (CompositeBlock, a PROGRAM's child blocks; CompositeDriver, a machine's I/O drivers): child 0's
// parameters first, then child 1's, each name behind its child's prefix ("gap.kg"), or as the
// child names it when the prefix is empty (an unnamed driver of a composite I/O driver).
//
// RT-safety: owner(), apply() and count() are as RT-safe as the children's param_count() and
// apply_param() (no allocation of their own); the rest is non-RT. Thread-safety: as Block.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::rt {

class ChildParams {
 public:
  /// The child that owns a parameter, and the parameter's index within it.
  struct Owner {
    Block* block{nullptr};  // nullptr: past the last child's parameters
    const std::string* prefix{nullptr};
    std::size_t index{0};
  };

  /// Adds a child after those added before. Non-RT, build time; the child outlives this.
  void add(std::string prefix, Block& child);

  /// Each child's parameters, as "<prefix>.<param>". Non-RT, load time.
  void visit(ParamVisitor& v);
  /// Each child's problems, as "<prefix>.<field>". Non-RT.
  [[nodiscard]] std::vector<ParamError> validate() const;
  /// How many parameters the children have together.
  [[nodiscard]] std::size_t count() const;
  /// Who owns parameter `index` of this index space.
  [[nodiscard]] Owner owner(std::size_t index) const noexcept;
  /// Applies a staged write to its owner; nothing past the end. RT.
  void apply(std::size_t index, const ParamValue& v) const noexcept;
  /// Reads a parameter from its owner; an empty value past the end. Non-RT.
  [[nodiscard]] ParamValue read(std::size_t index) const;
  /// Every child's commit_params(). Non-RT.
  void commit() const;

 private:
  struct Child {
    std::string prefix;
    Block* block;
  };
  std::vector<Child> children_;
};

/// Appends `more` to `errs` with "<prefix>." in front of each field (the field alone for an
/// empty prefix, the prefix alone for an empty field). Non-RT.
void append_prefixed(std::vector<ParamError>& errs, std::string_view prefix,
                     std::vector<ParamError> more);

}  // namespace edm::rt
