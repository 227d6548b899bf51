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

// Forwards a child's parameters with "<child>." in front of each name (non-RT).
class PrefixedParams final : public ParamVisitor {
 public:
  PrefixedParams(const std::string& prefix, ParamVisitor& inner) : prefix_(prefix), inner_(inner) {}

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override {
    inner_.forward(prefix_ + "." + std::string(name), ref, spec);
  }

 private:
  const std::string& prefix_;
  ParamVisitor& inner_;
};

}  // namespace

void append_prefixed(std::vector<ParamError>& errs, std::string_view prefix,
                     std::vector<ParamError> more) {
  for (ParamError& e : more) {
    errs.push_back({e.field.empty() ? std::string(prefix) : std::string(prefix) + "." + e.field,
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

void CompositeBlock::visit_params(ParamVisitor& v) {
  for (Child& c : children_) {
    PrefixedParams p(c.name, v);
    c.block->visit_params(p);
  }
}

std::vector<ParamError> CompositeBlock::validate() const {
  std::vector<ParamError> errs;
  for (const Child& c : children_) {
    append_prefixed(errs, c.name, c.block->validate());
  }
  return errs;
}

std::size_t CompositeBlock::param_count() {
  std::size_t n = 0;
  for (Child& c : children_) {
    n += c.block->param_count();
  }
  return n;
}

std::vector<ParamError> CompositeBlock::stage_param(std::size_t index, const ParamValue& v) {
  for (Child& c : children_) {
    const std::size_t n = c.block->param_count();
    if (index < n) {
      std::vector<ParamError> errs;
      append_prefixed(errs, c.name, c.block->stage_param(index, v));
      return errs;
    }
    index -= n;
  }
  return Block::stage_param(index, v);
}

void CompositeBlock::apply_param(std::size_t index, const ParamValue& v) noexcept {
  for (Child& c : children_) {
    const std::size_t n = c.block->param_count();
    if (index < n) {
      c.block->apply_param(index, v);
      return;
    }
    index -= n;
  }
}

ParamValue CompositeBlock::read_param(std::size_t index) const {
  for (const Child& c : children_) {
    const std::size_t n = c.block->param_count();
    if (index < n) {
      return c.block->read_param(index);
    }
    index -= n;
  }
  return {};
}

void CompositeBlock::commit_params() {
  for (Child& c : children_) {
    c.block->commit_params();
  }
}

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
  return update_self(ctx);
}

BlockStatus CompositeBlock::step(Block& child, const CycleContext& ctx) noexcept {
  const BlockStatus s = child.update(ctx);
  if (s == BlockStatus::kFault) {
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
