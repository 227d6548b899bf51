#pragma once
// Base for C++ PROGRAM types (IEC 61131-3 PROGRAMs written in C++): sequencers that own child
// blocks and step them from their own update_self(), in whatever order their steps require.
//
// Children are added in the constructor (add_child) and are blocks like any other:
//  - their pins are variables `program.<instance>.<child>.<pin>` (listable, readable,
//    forceable, traceable, retainable);
//  - their parameters are variables `program.<instance>.<child>.<param>` (the same, and
//    writable at run time unless load-time only), set in YAML under the composite's `params`
//    as a nested map (`gap: {kg: 0.1}`) or a dotted key (`gap.kg: 0.1`), see docs/config.md;
//  - the composite connects them by member in bind_self(), which runs after the YAML wiring:
//      gap_.td_us.connect(td_.td_us);   // a child's output → a child's input
//      td_.td_count.follow(td_count);   // the composite's own input → a child's input
//    Nothing is wired by name, and no cell exists only to cross the composite's boundary.
// configure(), bind(), activate() and enter_safe_state() reach every child, then the composite
// itself. A child's configure() sees its own instance name ("cnc.job.drill.gap"), and a fault
// a child raises is reported under that name (fault_source()).
//
// RT-safety: update() and enter_safe_state() as for any block; the rest is non-RT.
// Use as `class DrillCycle : public BlockWithParams<DrillParams, CompositeBlock>`.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/child_params.hpp"

namespace edm::rt {

class CompositeBlock : public Block {
 public:
  /// The composite's own pins, then each child's as "<child>.<pin>".
  void visit_pins(PinVisitor& v) final;
  /// Each child's parameters as "<child>.<param>" (BlockWithParams puts the composite's own
  /// first).
  void visit_params(ParamVisitor& v) override;
  /// Each child's problems as "<child>.<field>".
  [[nodiscard]] std::vector<ParamError> validate() const override;
  [[nodiscard]] std::size_t param_count() override;
  std::vector<ParamError> stage_param(std::size_t index, const ParamValue& v) override;
  void apply_param(std::size_t index, const ParamValue& v) noexcept override;
  [[nodiscard]] ParamValue read_param(std::size_t index) const override;
  void commit_params() override;

  /// Configures every child (instance "<instance>.<child>"), then configure_self().
  std::vector<ParamError> configure(const BlockSetup& setup) final;
  /// bind_self() (the composite connects its children), then every child's bind().
  void bind() final;
  /// Activates every child, then activate_self().
  void activate() noexcept final;
  /// Every child's safe state first, then safe_state_self().
  void enter_safe_state(const SafeStateRequest& request) noexcept final;
  /// Forgets the last cycle's fault source, then update_self(). RT-safe.
  BlockStatus update(const CycleContext& ctx) noexcept final;
  [[nodiscard]] const char* fault_source() const noexcept final { return fault_source_; }
  /// A faulting child's cause when a child faulted this cycle, else the composite's own.
  [[nodiscard]] FaultCause fault_cause() const noexcept final {
    return child_cause_.text != nullptr ? child_cause_ : Block::fault_cause();
  }

  [[nodiscard]] std::size_t child_count() const noexcept { return children_.size(); }

 protected:
  /// Adds a child block named `name` and returns it. Constructor only.
  template <class B>
  B& add_child(std::string name) {
    auto block = std::make_unique<B>();
    B& ref = *block;
    child_params_.add(name, ref);
    children_.push_back({std::move(name), {}, std::move(block)});
    return ref;
  }

  /// Runs one cycle of a child; a fault is remembered as this cycle's fault source. RT-safe.
  BlockStatus step(Block& child, const CycleContext& ctx) noexcept;

  /// The composite's own pins: by default those declared with its table (pins_).
  virtual void visit_own_pins(PinVisitor& v) { pins_.visit(v); }
  virtual std::vector<ParamError> configure_self(const BlockSetup& /*setup*/) { return {}; }
  virtual void bind_self() {}
  virtual void activate_self() noexcept {}
  virtual void safe_state_self(const SafeStateRequest& /*request*/) noexcept {}
  virtual BlockStatus update_self(const CycleContext& ctx) noexcept = 0;

 private:
  struct Child {
    std::string name;
    std::string full_name;  // "<instance>.<name>", set by configure()
    std::unique_ptr<Block> block;
  };
  std::vector<Child> children_;
  ChildParams child_params_;  // the children's parameters, "<child>.<param>"
  const char* fault_source_{nullptr};
  FaultCause child_cause_{};
};

}  // namespace edm::rt
