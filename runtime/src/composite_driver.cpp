#include "edm/runtime/composite_driver.hpp"

namespace edm::rt {

namespace {

// Passes a child's parameters on as "<child>.<param>".
class PrefixedParams final : public ParamVisitor {
 public:
  PrefixedParams(const std::string& prefix, ParamVisitor& out) : prefix_(prefix), out_(out) {}

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override {
    const std::string full = prefix_ + "." + std::string(name);
    out_.forward(full, ref, spec);
  }

 private:
  const std::string& prefix_;
  ParamVisitor& out_;
};

}  // namespace

void CompositeDriver::add(std::string name, std::unique_ptr<IoDriver> driver) {
  children_.push_back({std::move(name), std::move(driver)});
}

void CompositeDriver::visit_pins(PinVisitor& v) {
  for (Child& c : children_) {
    c.driver->visit_pins(v);
  }
}

void CompositeDriver::visit_params(ParamVisitor& v) {
  for (Child& c : children_) {
    if (c.name.empty()) {
      c.driver->visit_params(v);
    } else {
      PrefixedParams p(c.name, v);
      c.driver->visit_params(p);
    }
  }
}

std::vector<ParamError> CompositeDriver::validate() const {
  std::vector<ParamError> errs;
  for (const Child& c : children_) {
    for (ParamError& e : c.driver->validate()) {
      e.field = c.name.empty() ? e.field : c.name + "." + e.field;
      errs.push_back(std::move(e));
    }
  }
  return errs;
}

std::size_t CompositeDriver::param_count() {
  std::size_t n = 0;
  for (Child& c : children_) {
    n += c.driver->param_count();
  }
  return n;
}

IoDriver* CompositeDriver::param_owner(std::size_t& index) const noexcept {
  for (const Child& c : children_) {
    const std::size_t n = c.driver->param_count();
    if (index < n) {
      return c.driver.get();
    }
    index -= n;
  }
  return nullptr;
}

std::vector<ParamError> CompositeDriver::stage_param(std::size_t index, const ParamValue& v) {
  IoDriver* d = param_owner(index);
  return d != nullptr ? d->stage_param(index, v)
                      : std::vector<ParamError>{{"", "no such parameter"}};
}

void CompositeDriver::apply_param(std::size_t index, const ParamValue& v) noexcept {
  if (IoDriver* d = param_owner(index)) {
    d->apply_param(index, v);
  }
}

ParamValue CompositeDriver::read_param(std::size_t index) const {
  IoDriver* d = param_owner(index);
  return d != nullptr ? d->read_param(index) : ParamValue{};
}

void CompositeDriver::commit_params() {
  for (Child& c : children_) {
    c.driver->commit_params();
  }
}

void CompositeDriver::bind() {
  for (Child& c : children_) {
    c.driver->bind();
  }
}

void CompositeDriver::activate() noexcept {
  for (Child& c : children_) {
    c.driver->activate();
  }
}

void CompositeDriver::read_inputs(const CycleContext& ctx) noexcept {
  for (Child& c : children_) {
    c.driver->read_inputs(ctx);
  }
}

void CompositeDriver::write_outputs(const CycleContext& ctx) noexcept {
  for (Child& c : children_) {
    c.driver->write_outputs(ctx);
  }
}

void CompositeDriver::enter_safe_state(const SafeStateRequest& request) noexcept {
  for (Child& c : children_) {
    c.driver->enter_safe_state(request);
  }
}

IoFault CompositeDriver::fault() const noexcept {
  for (const Child& c : children_) {
    if (const IoFault f = c.driver->fault(); f.code != 0) {
      return f;
    }
  }
  return {};
}

bool CompositeDriver::set_seed(std::uint64_t seed) {
  bool any = false;
  for (Child& c : children_) {
    any = c.driver->set_seed(seed) || any;
  }
  return any;
}

void CompositeDriver::start() {
  for (Child& c : children_) {
    c.driver->start();
  }
}

bool CompositeDriver::wall_time_io() const noexcept {
  for (const Child& c : children_) {
    if (c.driver->wall_time_io()) {
      return true;
    }
  }
  return false;
}

void CompositeDriver::stop() noexcept {
  for (auto it = children_.rbegin(); it != children_.rend(); ++it) {
    it->driver->stop();
  }
}

}  // namespace edm::rt
