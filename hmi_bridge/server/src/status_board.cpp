#include "edm/bridge/status_board.hpp"

#include <cstring>
#include <stdexcept>
#include <thread>
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
  publish(s);
}

void StatusBoard::publish(const StatusSnapshot& s) noexcept {
  std::array<std::uint64_t, kWords> w{};
  std::memcpy(w.data(), &s, sizeof s);
  const std::uint64_t v = version_.load(std::memory_order_relaxed);
  version_.store(v + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  for (std::size_t i = 0; i < kWords; ++i) {
    words_[i].store(w[i], std::memory_order_relaxed);
  }
  version_.store(v + 2, std::memory_order_release);
}

bool StatusBoard::read(StatusSnapshot& out) const noexcept {
  std::array<std::uint64_t, kWords> w{};
  for (unsigned attempt = 0;; ++attempt) {
    const std::uint64_t v1 = version_.load(std::memory_order_acquire);
    if (v1 == 0) {
      return false;
    }
    if ((v1 & 1u) == 0) {
      for (std::size_t i = 0; i < kWords; ++i) {
        w[i] = words_[i].load(std::memory_order_relaxed);
      }
      std::atomic_thread_fence(std::memory_order_acquire);
      if (version_.load(std::memory_order_relaxed) == v1) {
        std::memcpy(static_cast<void*>(&out), w.data(), sizeof out);
        return true;
      }
    }
    if (attempt > 64) {
      std::this_thread::yield();  // the writer was preempted mid-publish (reader side only)
    }
  }
}

}  // namespace edm::bridge
