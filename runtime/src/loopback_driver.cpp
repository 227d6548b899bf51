#include "edm/runtime/loopback_driver.hpp"

namespace edm::rt {

std::vector<ParamError> LoopbackDriver::configure(const BlockSetup& /*setup*/) {
  channels_.clear();
  for (std::int64_t k = 0; k < params_.channels; ++k) {
    auto c = std::make_unique<Channel>();
    const std::string n = std::to_string(k);
    c->ai = "ai" + n;
    c->ao = "ao" + n;
    c->di = "di" + n;
    c->dout = "do" + n;
    channels_.push_back(std::move(c));
  }
  return {};
}

void LoopbackDriver::visit_pins(PinVisitor& v) {
  for (auto& c : channels_) {
    v.output(c->ai, c->ai_pin);
    v.input(c->ao, c->ao_pin);
  }
  for (auto& c : channels_) {
    v.output(c->di, c->di_pin);
    v.input(c->dout, c->do_pin);
  }
}

void LoopbackDriver::read_inputs(const CycleContext& /*ctx*/) noexcept {
  for (auto& c : channels_) {
    c->ai_pin.set(c->ao_latched);
    c->di_pin.set(c->do_latched);
  }
}

void LoopbackDriver::write_outputs(const CycleContext& ctx) noexcept {
  const bool safe = is_safe_state(ctx.state);
  for (auto& c : channels_) {
    c->ao_latched = safe ? 0.0 : c->ao_pin.get();
    c->do_latched = safe ? false : c->do_pin.get();
  }
}

void LoopbackDriver::enter_safe_state(const SafeStateRequest& /*request*/) noexcept {
  safe_entries_.fetch_add(1);
  for (auto& c : channels_) {
    c->ao_latched = 0.0;
    c->do_latched = false;
  }
}

IoFault LoopbackDriver::fault() const noexcept {
  const int code = fault_code_.load();
  return code == 0 ? IoFault{} : IoFault{code, "loopback: injected fault"};
}

void register_runtime_drivers(DriverRegistry& r) {
  r.add<LoopbackDriver>("loopback", "loopback I/O: outputs come back as inputs next cycle");
}

}  // namespace edm::rt
