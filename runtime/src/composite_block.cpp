#include "edm/runtime/composite_block.hpp"

namespace edm::rt {

namespace {

// Forwards a child's pins with "<child>." in front of each name (load time only).
class PrefixedPins final : public PinVisitor {
 public:
  PrefixedPins(const std::string& prefix, PinVisitor& inner) : prefix_(prefix), inner_(inner) {}

 protected:
  void on_pin(std::string_view name, PinRef ref, std::string_view unit) override {
    inner_.forward(prefix_ + "." + std::string(name), ref, unit);
  }

 private:
  const std::string& prefix_;
  PinVisitor& inner_;
};

}  // namespace

void CompositeBlock::visit_pins(PinVisitor& v) {
  visit_own_pins(v);
  for (Child& c : children_) {
    PrefixedPins p(c.name, v);
    c.block->visit_pins(p);
  }
}

void CompositeBlock::visit_params(ParamVisitor& v) { child_params_.visit(v); }

std::vector<ParamError> CompositeBlock::validate() const { return child_params_.validate(); }

std::size_t CompositeBlock::param_count() { return child_params_.count(); }

std::vector<ParamError> CompositeBlock::stage_param(std::size_t index, const ParamValue& v) {
  const ChildParams::Owner o = child_params_.owner(index);
  if (o.block == nullptr) {
    return Block::stage_param(o.index, v);
  }
  std::vector<ParamError> errs;
  append_prefixed(errs, *o.prefix, o.block->stage_param(o.index, v));
  return errs;
}

void CompositeBlock::apply_param(std::size_t index, const ParamValue& v) noexcept {
  child_params_.apply(index, v);
}

ParamValue CompositeBlock::read_param(std::size_t index) const { return child_params_.read(index); }

void CompositeBlock::commit_params() { child_params_.commit(); }

std::vector<ParamError> CompositeBlock::configure(const BlockSetup& setup) {
  std::vector<ParamError> errs;
  for (Child& c : children_) {
    c.full_name = std::string(setup.instance) + "." + c.name;
    BlockSetup child_setup = setup;
    child_setup.instance = c.full_name;
    append_prefixed(errs, c.name, c.block->configure(child_setup));
  }
  for (ParamError& e : configure_self(setup)) {
    errs.push_back(std::move(e));
  }
  return errs;
}

void CompositeBlock::bind() {
  bind_self();
  for (Child& c : children_) {
    c.block->bind();
  }
}

void CompositeBlock::activate() noexcept {
  for (Child& c : children_) {
    c.block->activate();
  }
  activate_self();
}

void CompositeBlock::enter_safe_state(const SafeStateRequest& request) noexcept {
  for (Child& c : children_) {
    c.block->enter_safe_state(request);
  }
  safe_state_self(request);
}

BlockStatus CompositeBlock::update(const CycleContext& ctx) noexcept {
  fault_source_ = nullptr;
  child_cause_ = {};
  return update_self(ctx);
}

BlockStatus CompositeBlock::step(Block& child, const CycleContext& ctx) noexcept {
  const BlockStatus s = child.update(ctx);
  if (s == BlockStatus::kFault) {
    child_cause_ = child.fault_cause();  // with the source: the last child that faulted
    if (const char* inner = child.fault_source(); inner != nullptr) {
      fault_source_ = inner;
    } else {
      for (const Child& c : children_) {
        if (c.block.get() == &child) {
          fault_source_ = c.full_name.c_str();
        }
      }
    }
  }
  return s;
}

}  // namespace edm::rt
