#include "edm/runtime/composite_driver.hpp"

namespace edm::rt {

void CompositeDriver::add(std::string name, std::unique_ptr<IoDriver> driver) {
  params_.add(std::move(name), *driver);
  children_.push_back(std::move(driver));
}

void CompositeDriver::visit_pins(PinVisitor& v) {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->visit_pins(v);
  }
}

void CompositeDriver::visit_params(ParamVisitor& v) { params_.visit(v); }

std::vector<ParamError> CompositeDriver::validate() const { return params_.validate(); }

std::size_t CompositeDriver::param_count() { return params_.count(); }

std::vector<ParamError> CompositeDriver::stage_param(std::size_t index, const ParamValue& v) {
  const ChildParams::Owner o = params_.owner(index);
  return o.block != nullptr ? o.block->stage_param(o.index, v)
                            : std::vector<ParamError>{{"", "no such parameter"}};
}

void CompositeDriver::apply_param(std::size_t index, const ParamValue& v) noexcept {
  params_.apply(index, v);
}

ParamValue CompositeDriver::read_param(std::size_t index) const { return params_.read(index); }

void CompositeDriver::commit_params() { params_.commit(); }

void CompositeDriver::bind() {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->bind();
  }
}

void CompositeDriver::activate() noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->activate();
  }
}

void CompositeDriver::read_inputs(const CycleContext& ctx) noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->read_inputs(ctx);
  }
}

void CompositeDriver::write_outputs(const CycleContext& ctx) noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->write_outputs(ctx);
  }
}

void CompositeDriver::enter_safe_state(const SafeStateRequest& request) noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->enter_safe_state(request);
  }
}

IoFault CompositeDriver::fault() const noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    if (const IoFault f = d->fault(); f.code != 0) {
      return f;
    }
  }
  return {};
}

bool CompositeDriver::set_seed(std::uint64_t seed) {
  bool any = false;
  for (const std::unique_ptr<IoDriver>& d : children_) {
    any = d->set_seed(seed) || any;
  }
  return any;
}

void CompositeDriver::start() {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    d->start();
  }
}

bool CompositeDriver::wall_time_io() const noexcept {
  for (const std::unique_ptr<IoDriver>& d : children_) {
    if (d->wall_time_io()) {
      return true;
    }
  }
  return false;
}

void CompositeDriver::stop() noexcept {
  for (auto it = children_.rbegin(); it != children_.rend(); ++it) {
    (*it)->stop();
  }
}

}  // namespace edm::rt
