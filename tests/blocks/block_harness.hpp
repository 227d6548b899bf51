#pragma once
// A harness that runs one block outside the runtime: set params, validate → configure →
// activate, wire inputs to test-owned outputs by pin name, and step update() with a CycleContext
// on an exact time grid (release = cycle·period).
//
// Not thread-safe; test code only (it allocates freely outside step()).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "edm/runtime/block.hpp"
#include "support/param_access.hpp"

namespace edm::blocks::test {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Formats validate()/configure() errors for assertion messages.
inline std::string describe(const std::vector<rt::ParamError>& errs) {
  std::string out;
  for (const auto& e : errs) {
    out += (e.field.empty() ? std::string("<block>") : e.field) + ": " + e.message + "; ";
  }
  return out;
}

template <class B>
class BlockHarness {
 public:
  using Params = typename B::Params;

  explicit BlockHarness(rt::Duration period = std::chrono::milliseconds(1)) : period_(period) {
    struct Collect final : rt::PinVisitor {
      std::map<std::string, rt::PinRef, std::less<>>* pins;
      void on_pin(std::string_view name, rt::PinRef ref, std::string_view /*unit*/) override {
        pins->emplace(std::string(name), ref);
      }
    } c;
    c.pins = &pins_;
    block_.visit_pins(c);
  }

  B& block() noexcept { return block_; }
  [[nodiscard]] rt::Duration period() const noexcept { return period_; }
  [[nodiscard]] double dt_s() const noexcept { return static_cast<double>(period_.count()) / 1e9; }

  /// validate → configure → commit_params → activate, in the runtime's order; returns the first
  /// non-empty error list (and stops there).
  std::vector<rt::ParamError> start(const Params& p) {
    block_.set_params(p);
    return start();
  }
  /// start(p) for a test that expects the parameters to be accepted (a refusal fails the test).
  void start_ok(const Params& p) {
    const auto errs = start(p);
    EXPECT_TRUE(errs.empty()) << describe(errs);
  }
  std::vector<rt::ParamError> start() {
    if (auto errs = block_.validate(); !errs.empty()) {
      return errs;
    }
    if (auto errs = block_.configure({"test.block", period_}); !errs.empty()) {
      return errs;
    }
    block_.commit_params();
    block_.activate();
    cycle_ = 0;
    return {};
  }

  /// A test-owned output wired to the block's input `name` (created on first use).
  template <rt::PinValue T>
  rt::Output<T>& source(std::string_view name) {
    auto it = pins_.find(name);
    if (it == pins_.end() || it->second.template as_input<T>() == nullptr) {
      ADD_FAILURE() << "no input pin '" << name << "' of that type";
      static rt::Output<T> dummy;
      return dummy;
    }
    auto& src = sources<T>()[std::string(name)];
    it->second.template as_input<T>()->connect(src);
    return src;
  }
  rt::Output<double>& in(std::string_view name = "in") { return source<double>(name); }

  /// Reads the block's output pin `name`.
  template <rt::PinValue T>
  [[nodiscard]] T out(std::string_view name) const {
    auto it = pins_.find(name);
    if (it == pins_.end() || it->second.template as_output<T>() == nullptr) {
      ADD_FAILURE() << "no output pin '" << name << "' of that type";
      return T{};
    }
    return it->second.template as_output<T>()->get();
  }
  [[nodiscard]] double out(std::string_view name = "out") const { return out<double>(name); }

  /// The block's pin (input or output) for forcing/inspection tests.
  [[nodiscard]] rt::PinRef pin(std::string_view name) const {
    auto it = pins_.find(name);
    return it == pins_.end() ? rt::PinRef{} : it->second;
  }

  /// One update() at the current cycle, then advances the cycle.
  rt::BlockStatus step() {
    rt::CycleContext ctx;
    ctx.period = period_;
    ctx.dt_s = dt_s();
    ctx.cycle = cycle_;
    // Saturates instead of overflowing for the huge cycle counts some tests jump to.
    const auto max_cycle = period_.count() <= 0
                               ? std::uint64_t{0}
                               : static_cast<std::uint64_t>(
                                     std::numeric_limits<std::int64_t>::max() / period_.count());
    ctx.release =
        cycle_ <= max_cycle ? period_ * static_cast<std::int64_t>(cycle_) : rt::TimePoint::max();
    ctx.state = rt::MachineState::kRunning;
    ++cycle_;
    return block_.update(ctx);
  }
  /// Latches a command on the bool input `name`: drops it for one cycle if it was high, then
  /// raises it. Returns the status of the edge cycle.
  rt::BlockStatus rising_edge(std::string_view name = "start") {
    auto& s = source<bool>(name);
    if (s.get()) {
      s.set(false);
      step();
    }
    s.set(true);
    return step();
  }
  /// Sets input "in" to x, then step().
  rt::BlockStatus step(double x) {
    if (in_ == nullptr) {
      in_ = &in("in");
    }
    in_->set(x);
    return step();
  }

  [[nodiscard]] std::uint64_t cycle() const noexcept { return cycle_; }
  void set_cycle(std::uint64_t c) noexcept { cycle_ = c; }

  /// Index of parameter `name` for stage_param/apply_param/read_param (visit order).
  [[nodiscard]] std::size_t param_index(std::string_view name) {
    return ::edm::test::param_index(block_, name);
  }

  /// A runtime parameter write the way the runtime does it (support/param_access.hpp).
  std::vector<rt::ParamError> write_param(std::string_view name, const rt::ParamValue& v) {
    return ::edm::test::write_param(block_, name, v);
  }

 private:
  template <class T>
  std::map<std::string, rt::Output<T>, std::less<>>& sources() {
    if constexpr (std::is_same_v<T, bool>) {
      return bool_sources_;
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      return int_sources_;
    } else {
      return real_sources_;
    }
  }

  B block_;
  rt::Duration period_;
  std::uint64_t cycle_{0};
  std::map<std::string, rt::PinRef, std::less<>> pins_;
  // std::map nodes never move, so wires to these outputs stay valid.
  std::map<std::string, rt::Output<bool>, std::less<>> bool_sources_;
  std::map<std::string, rt::Output<std::int64_t>, std::less<>> int_sources_;
  std::map<std::string, rt::Output<double>, std::less<>> real_sources_;
  rt::Output<double>* in_{nullptr};
};

}  // namespace edm::blocks::test

// The names every block test uses unqualified, declared once for the suite instead of in each file.
namespace edm::blocks {
using namespace std::chrono_literals;
using rt::BlockStatus;
using test::BlockHarness;
using test::describe;
using test::kInf;
using test::kNaN;
}  // namespace edm::blocks
