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

PinRef CompositeBlock::find_pin(Block& block, std::string_view name) {
  struct Find final : PinVisitor {
    std::string_view want;
    PinRef found{};
    void on_pin(std::string_view n, PinRef r, std::string_view) override {
      if (n == want) {
        found = r;
      }
    }
  } f;
  f.want = name;
  block.visit_pins(f);
  return f.found;
}

void CompositeBlock::append_child_errors(std::vector<ParamError>& errs, std::string_view child_name,
                                         std::vector<ParamError> more) {
  for (ParamError& e : more) {
    errs.push_back(
        {e.field.empty() ? std::string(child_name) : std::string(child_name) + "." + e.field,
         std::move(e.message)});
  }
}

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
    append_child_errors(errs, c.name, c.block->validate());
    append_child_errors(errs, c.name, c.block->configure(setup));
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
