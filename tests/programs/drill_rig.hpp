#pragma once
// A DeepHoleDrill driven from test cells: its own inputs are wired to outputs the test sets, its
// outputs and its children's are read by name (as variables would be).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "edm/programs/deep_hole_drill.hpp"

namespace edm::test {

using namespace std::chrono_literals;

// Drives the composite's own inputs from cells and reads its outputs.
struct Rig {
  programs::DeepHoleDrill drill;
  rt::Output<std::int64_t> td_sum_ns, td_count, n_open, n_short;
  rt::Output<double> z_mm;
  rt::Output<bool> start, comp{true};
  std::map<std::string, rt::PinRef> pins;
  rt::CycleContext ctx;

  explicit Rig(const programs::DeepHoleDrillParams& p) {
    drill.set_params(p);
    EXPECT_TRUE(drill.validate().empty());
    EXPECT_TRUE(drill.configure({"cycle.drill", 1ms}).empty());
    struct Collect final : rt::PinVisitor {
      std::map<std::string, rt::PinRef>* out;
      void on_pin(std::string_view n, rt::PinRef r, std::string_view) override {
        (*out)[std::string(n)] = r;
      }
    } c;
    c.out = &pins;
    drill.visit_pins(c);
    in<std::int64_t>("td_sum_ns").connect(td_sum_ns);
    in<std::int64_t>("td_count").connect(td_count);
    in<std::int64_t>("n_open").connect(n_open);
    in<std::int64_t>("n_short").connect(n_short);
    in<double>("z_mm").connect(z_mm);
    in<bool>("start").connect(start);
    in<bool>("enable_wear_comp").connect(comp);
    drill.bind();
    drill.activate();
    ctx.period = 1ms;
    ctx.dt_s = 0.001;
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
  double vz() { return out<double>("vz_cmd_mm_s"); }
  bool gen() { return out<bool>("gen_on"); }
  void sparks(std::int64_t n, double td_us) {
    td_count.set(n);
    td_sum_ns.set(static_cast<std::int64_t>(static_cast<double>(n) * td_us * 1000.0));
  }
  void step() {
    drill.update(ctx);
    ++ctx.cycle;
  }
};

}  // namespace edm::test
