// The op table's states (issue 31, item 6; issue 32, item 4): every op of the protocol against
// every state the machine can be in, through the real server. A request outside its states is
// refused invalid_state and changes nothing; inside them it is never refused for its state.
//
// The drill machine is built but its tasks do not run: the test stands in for the RT side (it
// drives the machine's state and takes the manual requests itself), so every state is exact —
// also "a jog sent and not taken yet", the state in which the tester's `home` and `touch`
// answered ok.
#include <gtest/gtest.h>

#include <set>

#include "bridge_fixture.hpp"
#include "edm/bridge/op_table.hpp"
#include "programs/sim_machine.hpp"

namespace edm::bridge::test {
namespace {

using machining::MotionBlock;
using machining::MotionKind;

class OpStates : public ::testing::Test {
 protected:
  void SetUp() override {
    rt_ = edm::test::build_sim_machine(
        rt::parse_config_file(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml"));
    server_ = start_server(*rt_);
    ASSERT_EQ(c_.connect(client_options(*server_)), Role::kOperator);
    for (const rt::Variable& v : rt_->variables().all()) {
      if (param_.empty() && !v.is_pin() && !v.load_time_only &&
          v.param_type == rt::ParamType::kReal && v.name.ends_with(".jog_v_max_mm_s")) {
        param_ = v.name;
      }
      if (pin_.empty() && v.is_pin() && v.kind == rt::VarKind::kOutput && v.owner != nullptr &&
          v.pin.type == rt::PinType::kReal) {
        pin_ = v.name;
      }
    }
    ASSERT_FALSE(param_.empty());
    ASSERT_FALSE(pin_.empty());
  }
  void TearDown() override {
    c_.close();
    if (server_) server_->stop();
  }

  /// Takes every queued manual request as the RT side would (and publishes "idle"); returns how
  /// many there were.
  int take_manual() {
    int n = 0;
    rt::ManualRequest r;
    while (rt_->manual().rt_poll(r, seen_)) ++n;
    rt::ManualStatus st;
    st.seen_seq = seen_;
    rt_->manual().rt_publish(st);
    return n;
  }
  rt::ManualRequest manual(rt::ManualOp op) {
    rt::ManualRequest r;
    r.op = op;
    r.axes = 0x4;
    r.value = op == rt::ManualOp::kJogVelocity ? 1.0 : 0.5;
    return r;
  }
  /// Puts the machine in `s`; returns how many manual requests that left queued.
  int set_state(OpState s) {
    take_manual();
    for (const std::string& f : rt_->variables().forced()) rt_->variables().unforce(f);
    rt::Machine& m = rt_->machine();
    if (m.state() == rt::MachineState::kOff) m.command(rt::MachineCommand::kPowerOn);
    m.command(rt::MachineCommand::kEstop);
    m.command(rt::MachineCommand::kReset);
    int queued = 0;
    switch (s) {
      case OpState::kOff: m.command(rt::MachineCommand::kPowerOff); break;
      case OpState::kIdle: break;
      case OpState::kJogging:
        queued = rt_->manual().request(manual(rt::ManualOp::kJogVelocity)) != 0 ? 1 : 0;
        break;
      case OpState::kManual:
        queued = rt_->manual().request(manual(rt::ManualOp::kJogDistance)) != 0 ? 1 : 0;
        break;
      case OpState::kRunning: m.command(rt::MachineCommand::kStart); break;
      case OpState::kHold:
        m.command(rt::MachineCommand::kStart);
        m.command(rt::MachineCommand::kHold);
        break;
      case OpState::kFault: {
        rt::Alarm a;
        a.code = rt::AlarmCode::kBlockFault;
        a.severity = rt::AlarmSeverity::kFault;
        a.source = "op_states_test";
        a.text = "a fault for the table";
        m.raise(a);
        break;
      }
      case OpState::kEstop: m.command(rt::MachineCommand::kEstop); break;
    }
    EXPECT_EQ(current_op_state(*rt_), s) << to_string(s);
    return queued;
  }

  /// A request of `spec` of this kind with valid parameters (it succeeds where the state allows
  /// it and nothing else stands in the way), after whatever it needs first.
  Json request_for(const OpSpec& spec, const OpKind& kind) {
    const std::string op(spec.name);
    const MotionBlock end = [] {
      MotionBlock b;
      b.kind = MotionKind::kEnd;
      b.line = 1;
      return b;
    }();
    if (op == "program.chunk" || op == "program.commit") {
      EXPECT_TRUE(c_.request("program.begin", {{"blocks", 1}}));
    }
    if (op == "program.commit") {
      EXPECT_TRUE(c_.request("program.chunk", {{"first", 0}, {"blocks", {to_json(end)}}}));
      const std::vector<MotionBlock> prog{end};
      return {{"checksum", format_checksum(program_checksum(prog))}};
    }
    if (op == "cycle.start") {
      EXPECT_EQ(rt_->job().load({end}), rt::LoadResult::kOk);
      return Json::object();
    }
    if (op == "hello") return {{"protocol", 1}};
    if (op == "subscribe") return {{"topics", {"alarm"}}};
    if (op == "program.begin") return {{"blocks", 1}};
    if (op == "program.chunk") return {{"first", 0}, {"blocks", {to_json(end)}}};
    if (op == "var.read") return {{"name", pin_}};
    if (op == "var.write") return {{"name", param_}, {"value", 2.0}};
    if (op == "var.force") return {{"name", pin_}, {"value", 0.0}};
    if (op == "var.unforce") return {{"name", pin_}};
    if (op == "trace.start") return {{"vars", {pin_}}};
    if (op == "feed.override") return {{"percent", 100}};
    if (op == "home") return {{"axes", "Z"}};
    if (op == "jog") {
      return kind.name == "velocity" ? Json{{"axis", "X"}, {"velocity", 1.0}}
                                     : Json{{"axis", "X"}, {"distance", 0.5}};
    }
    if (op == "touch") return {{"target", "z"}};
    if (op == "offset.set") return {{"frame", "G54"}, {"x", 1.0}};
    if (op == "electrode.set") return {{"length_mm", 300.0}};
    if (op == "electrode.change") {
      return {{"electrode", "E1"},
              {"kind", "tube"},
              {"size_mm", 1.0},
              {"material", "copper"},
              {"new_length_mm", 300.0}};
    }
    if (op == "electrode.measure") return {{"reference", "setter"}};
    if (op == "condition.set") return {{"E", 1}, {"field", "tdr_us"}, {"value", 8.0}};
    return Json::object();
  }

  std::unique_ptr<rt::Runtime> rt_;
  std::unique_ptr<Server> server_;
  Client c_;
  std::uint64_t seen_{0};
  std::string param_, pin_;
};

constexpr OpState kAllStates[] = {OpState::kOff,    OpState::kIdle,    OpState::kJogging,
                                  OpState::kManual, OpState::kRunning, OpState::kHold,
                                  OpState::kFault,  OpState::kEstop};
static_assert(std::size(kAllStates) == static_cast<std::size_t>(kOpStateCount));

/// Every kind of an op: its own, and jog's second ("velocity").
std::vector<const OpKind*> kinds_of(const OpSpec& op) {
  std::vector<const OpKind*> k{&op.kind};
  if (!op.kind_field.empty()) k.push_back(&op.field_kind);
  return k;
}

TEST(OpStateTable, stops_are_never_refused) {
  for (const char* name : {"estop", "jog.stop", "cycle.stop"}) {
    const OpSpec* op = find_op(name);
    ASSERT_NE(op, nullptr) << name;
    for (OpState s : {OpState::kJogging, OpState::kManual, OpState::kRunning, OpState::kHold}) {
      if (std::string_view(name) != "cycle.stop" || s == OpState::kRunning || s == OpState::kHold) {
        EXPECT_TRUE(allowed_in(op_kind(*op, Json::object()), s)) << name << " in " << to_string(s);
      }
    }
  }
}

TEST(OpStateTable, a_jog_is_judged_by_its_kind) {
  const OpSpec* jog = find_op("jog");
  ASSERT_NE(jog, nullptr);
  EXPECT_EQ(op_kind(*jog, {{"axis", "X"}, {"velocity", 1.0}}).name, "velocity");
  EXPECT_EQ(op_kind(*jog, {{"axis", "X"}, {"distance", 1.0}}).name, "distance");
  EXPECT_EQ(op_kind(*jog, Json::object()).name, "distance") << "neither: judged as a distance";
  EXPECT_TRUE(allowed_in(op_kind(*jog, {{"velocity", 1.0}}), OpState::kJogging));
  EXPECT_FALSE(allowed_in(op_kind(*jog, {{"distance", 1.0}}), OpState::kJogging));
}

TEST_F(OpStates, every_op_in_every_state_is_run_or_refused_as_the_table_says) {
  int refused = 0;
  int run = 0;
  for (const OpSpec& spec : op_table()) {
    for (const OpKind* kind : kinds_of(spec)) {
      for (const OpState state : kAllStates) {
        const std::string what = std::string(spec.name) + (kind->name.empty() ? "" : " ") +
                                 std::string(kind->name) + " in " + std::string(to_string(state));
        const int queued = set_state(state);
        const Json params = request_for(spec, *kind);
        // What a refusal must leave as it was.
        const rt::MachineState machine_before = rt_->machine().state();
        const std::uint64_t offsets_before = rt_->work_offsets().generation();
        const double feed_before = rt_->machine().feed_override();
        const std::size_t forced_before = rt_->variables().forced().size();
        const std::optional<double> param_before = rt_->variables().read(param_);

        const Reply r = c_.request(std::string(spec.name), params);
        const bool state_refusal = !r.ok && r.code == ErrorCode::kInvalidState &&
                                   r.message.find("is not allowed in") != std::string::npos;
        const int taken = take_manual();
        if (allowed_in(*kind, state)) {
          ++run;
          EXPECT_FALSE(state_refusal) << what << ": " << r.message;
          const bool motion = spec.name == "home" || spec.name == "jog" || spec.name == "touch" ||
                              spec.name == "jog.stop";
          if (motion) {
            EXPECT_TRUE(r.ok) << what << ": " << r.message;
            EXPECT_EQ(taken, queued + 1) << what << ": the request reached the RT side";
          }
        } else {
          ++refused;
          EXPECT_TRUE(state_refusal) << what << ": " << (r.ok ? r.body.dump() : r.message);
          EXPECT_NE(r.message.find(to_string(state)), std::string::npos) << r.message;
          EXPECT_EQ(taken, queued) << what << ": nothing reached the RT side";
          EXPECT_EQ(rt_->machine().state(), machine_before) << what;
          EXPECT_EQ(rt_->work_offsets().generation(), offsets_before) << what;
          EXPECT_EQ(rt_->machine().feed_override(), feed_before) << what;
          EXPECT_EQ(rt_->variables().forced().size(), forced_before) << what;
          EXPECT_EQ(rt_->variables().read(param_), param_before) << what;
        }
        if (spec.name == "program.chunk" || spec.name == "program.commit") {
          c_.request("program.abort");
        }
        if (spec.name == "trace.start") c_.request("trace.stop");
      }
    }
  }
  std::printf("op-state table: %d (op, state) pairs run, %d refused\n", run, refused);
  EXPECT_GT(refused, 40);
}

TEST_F(OpStates, a_request_sent_in_the_same_write_as_a_jog_is_judged_with_the_jog_pending) {
  set_state(OpState::kIdle);
  // Nothing takes the requests (the RT side is this test): the jog stays pending, as it is for
  // up to a cycle when both lines arrive in one write.
  const Reply jog = c_.request("jog", {{"axis", "X"}, {"distance", 0.5}});
  ASSERT_TRUE(jog) << jog.message;
  for (const auto& [op, params] :
       std::vector<std::pair<const char*, Json>>{{"home", {{"axes", "Z"}}},
                                                 {"touch", {{"target", "z"}}},
                                                 {"jog", {{"axis", "Y"}, {"distance", 1.0}}},
                                                 {"jog", {{"axis", "Y"}, {"velocity", 1.0}}},
                                                 {"cycle.start", Json::object()}}) {
    const Reply r = c_.request(op, params);
    expect_error(r, ErrorCode::kInvalidState);
    EXPECT_NE(r.message.find("READY with a manual operation running"), std::string::npos)
        << op << ": " << r.message;
  }
  // A stop is queued behind the jog; what is sent after the stop is judged as after it.
  ASSERT_TRUE(c_.request("jog.stop"));
  EXPECT_TRUE(c_.request("touch", {{"target", "z"}}));
  EXPECT_EQ(take_manual(), 3) << "jog, stop, touch: in that order, none lost";
}

}  // namespace
}  // namespace edm::bridge::test
