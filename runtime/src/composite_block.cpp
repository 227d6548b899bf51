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

std::vector<ParamError> CompositeBlock::configure(const BlockSetup& setup) {
  std::vector<ParamError> errs;
  for (Child& c : children_) {
    for (ParamError& e : c.block->validate()) {
      errs.push_back({e.field.empty() ? c.name : c.name + "." + e.field, e.message});
    }
    for (ParamError& e : c.block->configure(setup)) {
      errs.push_back({e.field.empty() ? c.name : c.name + "." + e.field, e.message});
    }
    c.block->commit_params();
  }
  for (ParamError& e : configure_self(setup)) {
    errs.push_back(std::move(e));
  }
  return errs;
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

}  // namespace edm::rt
