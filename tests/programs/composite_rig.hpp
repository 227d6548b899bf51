#pragma once
// A composite program driven from test cells on a 1 ms cycle: its spark counters and start are
// wired to outputs the test sets, its outputs and its children's are read by name (as variables
// would be). Not RT-safe (allocates); not thread-safe (one test thread).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "edm/programs/register.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/type_registry.hpp"

namespace edm::test {

/// True when `type` is one of the built-in program types.
inline bool is_builtin_program(const char* type) {
  rt::BlockRegistry r;
  programs::register_builtin_programs(r);
  return r.create(type) != nullptr;
}

template <class Block>
struct CompositeRig {
  Block block;
  rt::Output<std::int64_t> td_sum_ns, td_count, n_open, n_short;
  rt::Output<bool> start;
  std::map<std::string, rt::PinRef> pins;
  rt::CycleContext ctx;

  explicit CompositeRig(const typename Block::Params& p) { block.set_params(p); }
  // Held by reference in derived rigs: never copied.
  CompositeRig(const CompositeRig&) = delete;
  CompositeRig& operator=(const CompositeRig&) = delete;

  /// Validates and configures the block as `task`, collects its pins and wires the spark counters
  /// and start; the caller wires the rest, then calls activate().
  void configure(const char* task) {
    EXPECT_TRUE(block.validate().empty());
    EXPECT_TRUE(block.configure({task, std::chrono::milliseconds(1)}).empty());
    struct Collect final : rt::PinVisitor {
      std::map<std::string, rt::PinRef>* out;
      void on_pin(std::string_view n, rt::PinRef r, std::string_view) override {
        (*out)[std::string(n)] = r;
      }
    } c;
    c.out = &pins;
    block.visit_pins(c);
    in<std::int64_t>("td_sum_ns").connect(td_sum_ns);
    in<std::int64_t>("td_count").connect(td_count);
    in<std::int64_t>("n_open").connect(n_open);
    in<std::int64_t>("n_short").connect(n_short);
    in<bool>("start").connect(start);
    ctx.period = std::chrono::milliseconds(1);
    ctx.dt_s = 0.001;
  }
  void activate() {
    block.bind();
    block.activate();
  }
  template <class T>
  rt::Input<T>& in(const std::string& n) {
    return *pins.at(n).as_input<T>();
  }
  template <class T>
  T out(const std::string& n) {
    return pins.at(n).as_output<T>()->get();
  }

  std::int64_t state() { return out<std::int64_t>("state"); }
  bool gen() { return out<bool>("gen_on"); }
  /// `n` sparks this cycle at a mean delay `td_us`.
  void sparks(std::int64_t n, double td_us) {
    td_count.set(n);
    td_sum_ns.set(static_cast<std::int64_t>(static_cast<double>(n) * td_us * 1000.0));
  }
};

}  // namespace edm::test
