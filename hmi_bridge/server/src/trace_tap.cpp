#include "edm/bridge/trace_tap.hpp"

#include <stdexcept>
#include <thread>

namespace edm::bridge {

TraceTap::TraceTap(std::string task_name) : task_name_(std::move(task_name)) {}

void TraceTap::on_cycle_end(const rt::CycleContext& ctx) noexcept {
  busy_.store(true, std::memory_order_seq_cst);
  if (armed_.load(std::memory_order_seq_cst)) {
    if (!ring_.push(sampler_.sample(ctx.release, ctx.cycle))) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  busy_.store(false, std::memory_order_release);
}

void TraceTap::configure(const std::vector<rt::PinRef>& pins) {
  armed_.store(false, std::memory_order_seq_cst);
  while (busy_.load(std::memory_order_seq_cst)) {
    std::this_thread::yield();  // non-RT side waits for the RT side to leave on_cycle_end()
  }
  try {
    sampler_.assign(pins);
  } catch (const std::invalid_argument&) {
    armed_.store(sampler_.size() > 0, std::memory_order_seq_cst);  // refused: as it was
    throw;
  }
  ring_.consume_all([](const rt::TraceSample&) {});
  armed_.store(sampler_.size() > 0, std::memory_order_seq_cst);
}

std::size_t TraceTap::drain(std::vector<rt::TraceSample>& out, std::size_t max) {
  std::size_t n = 0;
  rt::TraceSample s;
  while (n < max && ring_.pop(s)) {
    out.push_back(s);
    ++n;
  }
  return n;
}

}  // namespace edm::bridge
