#include "edm/bridge/trace_tap.hpp"

#include <stdexcept>
#include <thread>

namespace edm::bridge {

TraceTap::TraceTap(std::string task_name) : task_name_(std::move(task_name)) {}

void TraceTap::on_cycle_end(const rt::CycleContext& ctx) noexcept {
  busy_.store(true, std::memory_order_seq_cst);
  if (armed_.load(std::memory_order_seq_cst)) {
    rt::TraceSample s;
    s.release = ctx.release;
    s.cycle = ctx.cycle;
    s.n = n_;
    for (std::uint32_t i = 0; i < n_; ++i) {
      s.v[i] = rt::read_pin_as_double(pins_[i]);
    }
    if (!ring_.push(s)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  busy_.store(false, std::memory_order_release);
}

void TraceTap::configure(const std::vector<rt::PinRef>& pins) {
  if (pins.size() > rt::kMaxTraceVarsPerTask) {
    throw std::invalid_argument("trace: too many variables for one task");
  }
  armed_.store(false, std::memory_order_seq_cst);
  while (busy_.load(std::memory_order_seq_cst)) {
    std::this_thread::yield();  // non-RT side waits for the RT side to leave on_cycle_end()
  }
  for (std::size_t i = 0; i < pins.size(); ++i) {
    pins_[i] = pins[i];
  }
  n_ = static_cast<std::uint32_t>(pins.size());
  ring_.consume_all([](const rt::TraceSample&) {});
  if (n_ > 0) {
    armed_.store(true, std::memory_order_seq_cst);
  }
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
