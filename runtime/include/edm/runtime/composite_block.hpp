#pragma once
// Base for C++ PROGRAM types (IEC 61131-3 PROGRAMs written in C++): sequencers that own child
// blocks and step them from their own update(), in whatever order their steps require.
//
// Children are added in the constructor (add_child). Their pins appear as variables
// `program.<instance>.<child>.<pin>` (listable, readable, forceable, traceable, retainable), and
// the composite wires them in C++ (Input::connect) — wires are still resolved once, at load.
// configure(), activate() and enter_safe_state() reach every child, then the composite itself.
// Children's parameters are set by the composite (from its own Params) before configure();
// they are not separate variables.
//
// RT-safety: update() and enter_safe_state() as for any block; the rest is non-RT.
// Use as `class DrillCycle : public BlockWithParams<DrillParams, CompositeBlock>`.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"

namespace edm::rt {

class CompositeBlock : public Block {
 public:
  /// The composite's own pins, then each child's as "<child>.<pin>".
  void visit_pins(PinVisitor& v) final;
  /// Configures every child (with the composite's setup), then configure_self().
  std::vector<ParamError> configure(const BlockSetup& setup) final;
  /// Activates every child, then activate_self().
  void activate() noexcept final;
  /// Every child's safe state first, then safe_state_self().
  void enter_safe_state(const SafeStateRequest& request) noexcept final;

  [[nodiscard]] std::size_t child_count() const noexcept { return children_.size(); }

 protected:
  /// Adds a child block named `name` and returns it. Constructor only.
  template <class B>
  B& add_child(std::string name) {
    auto block = std::make_unique<B>();
    B& ref = *block;
    children_.push_back({std::move(name), std::move(block)});
    return ref;
  }

  /// Connects the child's input `pin` to `source` (configure time). A missing or mistyped pin
  /// is reported as "<child>.<pin>: internal wire: no such input".
  template <PinValue T>
  static void wire_child(std::vector<ParamError>& errs, Block& child, std::string_view child_name,
                         std::string_view pin, const Output<T>& source) {
    Input<T>* in = find_pin(child, pin).template as_input<T>();
    if (in == nullptr) {
      errs.push_back(
          {std::string(child_name) + "." + std::string(pin), "internal wire: no such input"});
      return;
    }
    in->connect(source);
  }
  /// The child's output `pin`, or nullptr with an error (configure time).
  template <PinValue T>
  static const Output<T>* child_output(std::vector<ParamError>& errs, Block& child,
                                       std::string_view child_name, std::string_view pin) {
    const Output<T>* out = find_pin(child, pin).template as_output<T>();
    if (out == nullptr) {
      errs.push_back(
          {std::string(child_name) + "." + std::string(pin), "internal wire: no such output"});
    }
    return out;
  }
  /// Appends a child's problems with "<child>." in front of each field.
  static void append_child_errors(std::vector<ParamError>& errs, std::string_view child_name,
                                  std::vector<ParamError> more);

  virtual void visit_own_pins(PinVisitor& /*v*/) {}
  virtual std::vector<ParamError> configure_self(const BlockSetup& /*setup*/) { return {}; }
  virtual void activate_self() noexcept {}
  virtual void safe_state_self(const SafeStateRequest& /*request*/) noexcept {}

 private:
  /// The pin named `name` of a block, or a null PinRef (load time only).
  static PinRef find_pin(Block& block, std::string_view name);

  struct Child {
    std::string name;
    std::unique_ptr<Block> block;
  };
  std::vector<Child> children_;
};

}  // namespace edm::rt
