#include "edm/bridge/status_board.hpp"

#include <stdexcept>
#include <type_traits>

namespace edm::bridge {

static_assert(std::is_trivially_copyable_v<StatusSnapshot>);

StatusBoard::StatusBoard(const rt::Machine& machine, const rt::JobStore& job,
                         std::vector<rt::PinRef> pins)
    : machine_(&machine), job_(&job) {
  if (pins.size() > kMaxStatusVars) {
    throw std::invalid_argument("bridge: at most 16 status variables");
  }
  for (std::size_t i = 0; i < pins.size(); ++i) {
    pins_[i] = pins[i];
  }
  n_pins_ = static_cast<std::uint32_t>(pins.size());
}

void StatusBoard::on_cycle_end(const rt::CycleContext& ctx) noexcept {
  publish_now(ctx.release, ctx.cycle);
}

void StatusBoard::publish_now(rt::TimePoint release, std::uint64_t cycle) noexcept {
  StatusSnapshot s;
  s.publication = ++publications_;
  s.release = release;
  s.cycle = cycle;
  s.state = machine_->state();
  s.cause = machine_->last_cause();
  s.job = job_->progress();
  s.n_vars = n_pins_;
  for (std::uint32_t i = 0; i < n_pins_; ++i) {
    s.vars[i] = rt::read_pin_as_double(pins_[i]);
  }
  board_.store(s);
}

bool StatusBoard::read(StatusSnapshot& out) const noexcept {
  const StatusSnapshot s = board_.load();
  if (s.publication == 0) {
    return false;
  }
  out = s;
  return true;
}

}  // namespace edm::bridge
