// Issue 31 item 13: every runtime-writable parameter has a physical range, and a write outside it
// is refused by the runtime's one write entry point (VariableRegistry::write), which the bridge's
// var.write, the Modbus server and the MQTT commands all call.
//
//   Specs      every registered block, PROGRAM and driver type declares a bounded range (finite,
//              lo < hi) for each runtime-writable number, with its default inside (SpecAudit).
//   EntryPoint over every writable parameter of a machine holding one instance of every type:
//              min and max accepted (or refused by a cross-field rule, never as out of range);
//              just outside, ±inf and NaN refused as out of range, the value unchanged.
//   Config     a value outside the range is an error at its file:line:col.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "edm/runtime/variables.hpp"
#include "edm/sim/params.hpp"
#include "params/params_rig.hpp"

namespace edm::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Every registered type's parameters through SpecAudit; the failures name type and parameter.
template <class Registry>
std::size_t audit_all(const Registry& registry, std::vector<std::string>& problems) {
  std::size_t writable = 0;
  for (const std::string& type : registry.names()) {
    auto block = registry.create(type);
    rt::SpecAudit audit;
    block->visit_params(audit);
    writable += audit.writable_numbers;
    for (const rt::ParamError& p : audit.problems) {
      problems.push_back(type + "." + p.field + ": " + p.message);
    }
  }
  return writable;
}

TEST(Specs, EveryWritableParameterOfEveryRegisteredTypeHasABoundedRangeHoldingItsDefault) {
  rt::BlockRegistry blocks;
  blocks::register_builtin_blocks(blocks);
  programs::register_builtin_programs(blocks);
  rt::DriverRegistry drivers;
  rt::register_runtime_drivers(drivers);
  sim::register_sim_driver(drivers);
  modbus::register_modbus_driver(drivers);
  std::vector<std::string> problems;
  const std::size_t writable = audit_all(blocks, problems) + audit_all(drivers, problems);
  for (const std::string& p : problems) {
    ADD_FAILURE() << p;
  }
  // The audit saw the parameters (a visitor that saw none would pass vacuously).
  EXPECT_GT(writable, 150u);
  RecordProperty("writable_numbers", static_cast<int>(writable));
}

TEST(Specs, EverySimulatorPresetKeepsItsWritableDefaultsInRange) {
  for (const std::string& preset : sim::preset_names()) {
    sim::SimDriverParams p;
    p.preset = preset;  // visit() loads the preset's plant first
    rt::SpecAudit audit;
    p.visit(audit);
    EXPECT_GT(audit.writable_numbers, 0u) << preset;
    for (const rt::ParamError& e : audit.problems) {
      ADD_FAILURE() << preset << ": " << e.field << ": " << e.message;
    }
  }
}

TEST(Specs, TheAuditRefusesAMissingRangeAnUnboundedOneAndADefaultOutside) {
  struct Bad {
    double none{1.0};
    double half{1.0};
    std::int64_t outside{7};
    rt::Duration lazy{};
    double load_time{1.0};
    bool flag{false};
    void visit(rt::ParamVisitor& v) {
      v.param("none", none, {.unit = "mm"});
      v.param("half", half, {.range = rt::kPositive});
      v.param("outside", outside, {.range = rt::closed(0, 5)});
      v.param("lazy", lazy, {.range = rt::closed(1.0, 1.0)});  // lo == hi: no range
      v.param("load_time", load_time, {.load_time_only = true});
      v.param("flag", flag);
    }
  } bad;
  rt::SpecAudit audit;
  bad.visit(audit);
  EXPECT_EQ(audit.writable_numbers, 4u);
  ASSERT_EQ(audit.problems.size(), 4u);
  EXPECT_EQ(audit.problems[0].field, "none");
  EXPECT_NE(audit.problems[0].message.find("without a bounded range (none)"), std::string::npos)
      << audit.problems[0].message;
  EXPECT_NE(audit.problems[1].message.find("(> 0)"), std::string::npos);
  EXPECT_EQ(audit.problems[2].message, "default outside its own range: must be in [0, 5] (got 7)");
  EXPECT_EQ(audit.problems[3].field, "lazy");
}

// --- The runtime's write entry point, over every writable parameter -------------------------

// Just outside a bound: the bound itself when it is open, else the next value of the type.
rt::ParamValue outside_low(const rt::Variable& v) {
  const rt::Range& r = v.param_range;
  switch (v.param_type) {
    case rt::ParamType::kInt:
      return rt::ParamValue::of_int(static_cast<std::int64_t>(std::ceil(r.lo)) -
                                    (r.lo_open ? 0 : 1));
    case rt::ParamType::kDuration: {
      const auto ns = static_cast<std::int64_t>(std::ceil(r.lo * 1e9));
      return rt::ParamValue::of_duration(rt::Duration{ns - (r.lo_open ? 0 : 1)});
    }
    default: return rt::ParamValue::of_real(r.lo_open ? r.lo : std::nextafter(r.lo, -kInf));
  }
}
rt::ParamValue outside_high(const rt::Variable& v) {
  const rt::Range& r = v.param_range;
  switch (v.param_type) {
    case rt::ParamType::kInt:
      return rt::ParamValue::of_int(static_cast<std::int64_t>(std::floor(r.hi)) +
                                    (r.hi_open ? 0 : 1));
    case rt::ParamType::kDuration: {
      const auto ns = static_cast<std::int64_t>(std::floor(r.hi * 1e9));
      return rt::ParamValue::of_duration(rt::Duration{ns + (r.hi_open ? 0 : 1)});
    }
    default: return rt::ParamValue::of_real(r.hi_open ? r.hi : std::nextafter(r.hi, kInf));
  }
}
// The bound itself when it is closed, else the nearest value inside.
rt::ParamValue at_low(const rt::Variable& v) {
  const rt::ParamValue o = outside_low(v);
  switch (v.param_type) {
    case rt::ParamType::kInt: return rt::ParamValue::of_int(o.i + 1);
    case rt::ParamType::kDuration: return rt::ParamValue::of_duration(rt::Duration{o.i + 1});
    default: return rt::ParamValue::of_real(std::nextafter(o.r, kInf));
  }
}
rt::ParamValue at_high(const rt::Variable& v) {
  const rt::ParamValue o = outside_high(v);
  switch (v.param_type) {
    case rt::ParamType::kInt: return rt::ParamValue::of_int(o.i - 1);
    case rt::ParamType::kDuration: return rt::ParamValue::of_duration(rt::Duration{o.i - 1});
    default: return rt::ParamValue::of_real(std::nextafter(o.r, -kInf));
  }
}

bool same(const rt::ParamValue& a, const rt::ParamValue& b) {
  return a.type == b.type && a.b == b.b && a.i == b.i &&
         (a.r == b.r || (std::isnan(a.r) && std::isnan(b.r)));
}

std::string text(const rt::ParamValue& v) {
  return std::string(rt::to_string(v.type)) + " " +
         (v.type == rt::ParamType::kReal ? std::to_string(v.r) : std::to_string(v.i));
}

class EntryPoint : public ::testing::Test {
 protected:
  void SetUp() override { rt_ = build_every_type(); }
  std::unique_ptr<rt::Runtime> rt_;
};

TEST_F(EntryPoint, EveryWritableParameterTakesItsBoundsAndRefusesWhatLiesOutside) {
  rt::VariableRegistry& vars = rt_->variables();
  std::size_t checked = 0;
  std::size_t cross_field = 0;
  for (const rt::Variable& v : vars.all()) {
    if (v.kind != rt::VarKind::kParam ||
        !rt::needs_range(v.param_type, {.load_time_only = v.load_time_only})) {
      continue;
    }
    SCOPED_TRACE(v.name + " " + v.range);
    ASSERT_TRUE(v.param_range.bounded()) << "no bounded range";
    ++checked;
    const rt::ParamValue before = *vars.read_param(v.name);

    // Just outside each bound, and ±inf and NaN: refused as out of range, nothing changed.
    std::vector<rt::ParamValue> bad{outside_low(v), outside_high(v)};
    if (v.param_type == rt::ParamType::kReal) {
      bad.push_back(rt::ParamValue::of_real(kInf));
      bad.push_back(rt::ParamValue::of_real(-kInf));
      bad.push_back(rt::ParamValue::of_real(kNaN));
    }
    for (const rt::ParamValue& x : bad) {
      const rt::VarStatus st = vars.write(v.name, x, /*apply_now=*/true);
      EXPECT_EQ(st.result, rt::VarResult::kInvalid) << text(x) << ": " << st.message;
      EXPECT_NE(st.message.find("out of range"), std::string::npos)
          << text(x) << ": " << st.message;
      EXPECT_TRUE(same(*vars.read_param(v.name), before)) << "changed by a refused " << text(x);
    }
    // The numeric form the Modbus server and MQTT use: ±inf and NaN refused, nothing changed.
    for (const double x : {kInf, -kInf, kNaN, 9.2e18, -9.2e18}) {
      const rt::VarStatus st = vars.write(v.name, x, /*apply_now=*/true);
      EXPECT_FALSE(st) << x;
      EXPECT_TRUE(same(*vars.read_param(v.name), before)) << "changed by a refused " << x;
    }

    // Each bound is accepted, or refused by a rule that ties it to another field; never as out
    // of range. The default is put back after each accepted one.
    for (const rt::ParamValue& x : {at_low(v), at_high(v)}) {
      const rt::VarStatus st = vars.write(v.name, x, /*apply_now=*/true);
      if (st) {
        EXPECT_TRUE(same(*vars.read_param(v.name), x)) << text(x);
        ASSERT_TRUE(vars.write(v.name, before, /*apply_now=*/true));
      } else {
        ++cross_field;
        EXPECT_EQ(st.result, rt::VarResult::kInvalid) << st.message;
        EXPECT_EQ(st.message.find("out of range"), std::string::npos) << st.message;
        EXPECT_TRUE(same(*vars.read_param(v.name), before));
      }
    }
  }
  EXPECT_GT(checked, 200u);  // one instance of every type, its children's parameters included
  // Cross-field rules (max >= min, retract speed <= its limit, ...) refuse a minority of bounds.
  EXPECT_LT(cross_field, checked);
  RecordProperty("checked", static_cast<int>(checked));
  RecordProperty("bounds_refused_by_cross_field_rules", static_cast<int>(cross_field));
}

TEST_F(EntryPoint, TheIssueWriteOfGapKgIsRefusedAndNamesTheRange) {
  rt::VariableRegistry& vars = rt_->variables();
  const std::string kg = "every.DeepHoleDrill.gap.kg";
  ASSERT_NE(vars.find(kg), nullptr);
  const double before = *vars.read(kg);
  // An MQTT Int64 metric at 2^63 - 1 arrives as this double.
  const rt::VarStatus st = vars.write(kg, 9223372036854775807.0);
  EXPECT_EQ(st.result, rt::VarResult::kInvalid);
  EXPECT_EQ(st.message, "'" + kg + "': out of range: must be in (0, 10] mm/s/us (got 9.22337e18)");
  EXPECT_EQ(*vars.read(kg), before);
  EXPECT_TRUE(vars.write(kg, 10.0, /*apply_now=*/true));
  EXPECT_EQ(*vars.read(kg), 10.0);
}

TEST_F(EntryPoint, ATimeParameterIsRangedInSeconds) {
  rt::VariableRegistry& vars = rt_->variables();
  const std::string tau = "every.LowPass.tau";
  const rt::VarStatus st = vars.write(tau, rt::ParamValue::of_duration(std::chrono::hours(2)));
  EXPECT_EQ(st.message, "'" + tau + "': out of range: must be in (0, 3600] s (got 7200)");
  EXPECT_TRUE(vars.write(tau, rt::ParamValue::of_duration(std::chrono::hours(1)), true));
}

// A block type whose stage_param() validates nothing: the entry point refuses for it.
struct LaxParams {
  double speed_mm_s{1.0};
  void visit(rt::ParamVisitor& v) {
    v.param("speed_mm_s", speed_mm_s, {.unit = "mm/s", .range = rt::closed(0.0, 10.0)});
  }
};
class Lax final : public rt::BlockWithParams<LaxParams> {
 public:
  std::vector<rt::ParamError> stage_param(std::size_t, const rt::ParamValue&) override {
    return {};
  }
  rt::BlockStatus update(const rt::CycleContext&) noexcept override { return rt::BlockStatus::kOk; }
};

TEST(EntryPointFirst, TheRangeIsCheckedBeforeTheBlockSeesTheWrite) {
  rt::BlockRegistry blocks;
  blocks.add<Lax>("Lax");
  rt::DriverRegistry drivers;
  rt::register_runtime_drivers(drivers);
  const rt::Config cfg = rt::parse_config_text(R"(version: 1
machine:
  name: lax
  io: {driver: loopback, task: t}
tasks:
  - {name: t, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: lax, type: Lax}
)",
                                               "lax.yaml");
  auto r = rt::Runtime::build(cfg, blocks, drivers);
  const rt::VarStatus st = r->variables().write("p.lax.speed_mm_s", 11.0, true);
  EXPECT_EQ(st.message, "'p.lax.speed_mm_s': out of range: must be in [0, 10] mm/s (got 11)");
  EXPECT_EQ(*r->variables().read("p.lax.speed_mm_s"), 1.0);
  EXPECT_TRUE(r->variables().write("p.lax.speed_mm_s", 10.0, true));
}

// --- Config load ----------------------------------------------------------------------------

TEST(Config, AValueOutsideTheRangeIsAnErrorAtItsPosition) {
  const std::string yaml = R"(version: 1
machine:
  name: cfg
  io: {driver: loopback, task: t}
tasks:
  - {name: t, interval: 1ms, priority: 0, programs: [p]}
programs:
  - name: p
    blocks:
      - {name: gap, type: GapControllerP, params: {kg: 9.2e18}}
      - {name: lp, type: LowPass, params: {tau: 7200s}}
)";
  try {
    (void)build_with_every_registry(yaml, "cfg.yaml");
    FAIL() << "accepted";
  } catch (const rt::ConfigError& e) {
    ASSERT_EQ(e.diagnostics().size(), 2u);
    EXPECT_EQ(e.diagnostics()[0].str(),
              "cfg.yaml:10:56: block 'gap' (GapControllerP): kg must be in (0, 10] (got 9.2e18)");
    EXPECT_EQ(e.diagnostics()[1].str(),
              "cfg.yaml:11:49: block 'lp' (LowPass): tau must be in (0, 3600] (got 7200)");
  }
}

}  // namespace
}  // namespace edm::test
