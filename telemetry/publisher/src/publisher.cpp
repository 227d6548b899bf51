#include "edm/telemetry/publisher.hpp"

#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/cycle_observer.hpp"
#include "edm/runtime/seqlock.hpp"
#include "edm/telemetry/command_gate.hpp"
#include "edm/telemetry/command_intake.hpp"

namespace edm::telemetry {

namespace {

namespace sp = sparkplug;

constexpr std::size_t kMaxPins = 64;

/// What the RT side publishes each cycle of the I/O task.
struct Snapshot {
  std::uint64_t cycle{0};  // 0: no cycle yet
  rt::MachineState state{rt::MachineState::kOff};
  rt::AlarmCode cause{rt::AlarmCode::kNone};
  rt::JobProgress job{};
  std::array<double, kMaxPins> pins{};
};

class SnapshotObserver final : public rt::CycleObserver {
 public:
  SnapshotObserver(const rt::Machine& machine, const rt::JobStore& job,
                   std::vector<rt::PinRef> pins)
      : machine_(machine), job_(job), pins_(std::move(pins)) {}

  /// RT-safe: reads atomics and pins, one seqlock store.
  void on_cycle_end(const rt::CycleContext& ctx) noexcept override {
    Snapshot s;
    s.cycle = ctx.cycle + 1;
    s.state = machine_.state();
    s.cause = machine_.last_cause();
    s.job = job_.progress();
    for (std::size_t i = 0; i < pins_.size(); ++i) s.pins[i] = rt::read_pin_as_double(pins_[i]);
    board_.store(s);
  }
  [[nodiscard]] Snapshot load() const noexcept { return board_.load(); }

 private:
  const rt::Machine& machine_;
  const rt::JobStore& job_;
  const std::vector<rt::PinRef> pins_;  // fixed before the tasks run
  rt::Seqlock<Snapshot> board_;
};

// The fixed device metrics, in this order, before the configured ones (docs/mqtt.md).
enum Fixed : std::size_t {
  kState,
  kAlarmCount,
  kAlarmActive,
  kLastCause,
  kJobOutcome,
  kJobBlock,
  kJobBlocks,
  kJobLine,
  kJobProgress,
  kJobsStarted,
  kFixedCount
};

sp::DataType metric_type(const rt::Variable& v) {
  if (v.is_pin()) {
    switch (v.pin.type) {
      case rt::PinType::kBool: return sp::DataType::kBoolean;
      case rt::PinType::kInt: return sp::DataType::kInt64;
      case rt::PinType::kReal: return sp::DataType::kDouble;
    }
  }
  switch (v.param_type) {
    case rt::ParamType::kBool: return sp::DataType::kBoolean;
    case rt::ParamType::kInt: return sp::DataType::kInt64;
    default: return sp::DataType::kDouble;  // REAL, TIME in seconds
  }
}

sp::Value typed(sp::DataType t, double x) {
  if (!std::isfinite(x)) return t == sp::DataType::kDouble ? sp::Value{x} : sp::Value{};
  switch (t) {
    case sp::DataType::kBoolean: return x != 0.0;
    case sp::DataType::kInt64: return static_cast<std::int64_t>(std::llround(x));
    default: return x;
  }
}

}  // namespace

struct Publisher::Impl {
  Impl(rt::Runtime& r, MqttConfig c)
      : rt(r), cfg(std::move(c)), gate(rt.variables(), cfg.commands_enabled, cfg.writable) {
    std::vector<rt::PinRef> pins;
    std::vector<sp::MetricDef> defs = {
        {"state", sp::DataType::kString, 0.0},
        {"alarms/count", sp::DataType::kUInt32, 0.0},
        {"alarms/active", sp::DataType::kString, 0.0},
        {"alarms/last_cause", sp::DataType::kString, 0.0},
        {"job/outcome", sp::DataType::kString, 0.0},
        {"job/block", sp::DataType::kUInt64, 0.0},
        {"job/blocks", sp::DataType::kUInt64, 0.0},
        {"job/line", sp::DataType::kInt32, 0.0},
        {"job/progress_pct", sp::DataType::kDouble, 0.0},
        {"job/jobs_started", sp::DataType::kUInt64, 0.0},
    };
    for (const MetricSpec& m : cfg.metrics) {
      const rt::Variable* v = rt.variables().find(m.var);
      defs.push_back({m.name, metric_type(*v), m.deadband});
      Source s;
      s.var = v;
      if (v->is_pin()) {
        s.pin_index = pins.size();
        pins.push_back(v->pin);
      }
      sources.push_back(s);
    }
    observer = std::make_unique<SnapshotObserver>(rt.machine(), rt.job(), std::move(pins));
    // The I/O task (the one with the driver), else the first: where the bridge's board is too.
    rt::Task* io_task = nullptr;
    for (const auto& t : rt.tasks()) {
      if (t->driver() != nullptr) io_task = t.get();
    }
    if (io_task == nullptr && !rt.tasks().empty()) io_task = rt.tasks().front().get();
    if (io_task != nullptr) io_task->add_observer(*observer);

    sp::EdgeNodeOptions o;
    o.host = cfg.host;
    o.port = cfg.port;
    o.group = cfg.group;
    o.node = cfg.node;
    o.device = cfg.device;
    o.client_id = cfg.client_id;
    o.keepalive_s = static_cast<int>(cfg.keepalive.count());
    o.username = cfg.username;
    o.password = cfg.password;
    o.tls = cfg.tls;
    o.device_metrics = std::move(defs);
    o.store_capacity = cfg.store_forward;
    o.heartbeat = cfg.heartbeat;
    o.log = [](const std::string& line) { spdlog::info("{}", line); };
    o.warn = [](const std::string& line) { spdlog::warn("{}", line); };
    // Commands: libmosquitto's thread only offers them to the intake (bounded); this thread
    // screens, decodes and logs them (quoted, rate-limited) and the gate writes what it may.
    IntakeOptions in;
    in.ncmd_topic = sp::Topic{cfg.group, sp::MessageType::kNCmd, cfg.node, ""}.str();
    in.dcmd_topic = sp::Topic{cfg.group, sp::MessageType::kDCmd, cfg.node, cfg.device}.str();
    in.broker = cfg.host + ":" + std::to_string(cfg.port);
    in.limits = cfg.limits;
    in.info = [](const std::string& line) { spdlog::info("{}", line); };
    in.warn = [](const std::string& line) { spdlog::warn("{}", line); };
    intake = std::make_unique<CommandIntake>(
        std::move(in), [this](sp::MessageType /*type*/, const sp::Metric& m, std::string& why) {
          return gate.apply(m, why);
        });
    node = std::make_unique<sp::EdgeNode>(
        std::move(o), [this](std::string_view topic, std::string_view payload, bool retained) {
          intake->offer(topic, payload, retained);
        });
  }

  // Commands first, so a rebirth request or a write is in this tick's births and counters.
  void step() {
    if (intake->process(CommandIntake::Clock::now())) node->request_rebirth();
    node->set_command_counters(
        {intake->accepted(), intake->refused(), intake->dropped(), intake->out_of_range()});
    const auto values = sample();
    node->tick(values, sp::now_ms());
  }

  std::vector<sp::Value> sample() {
    const Snapshot s = observer->load();
    std::vector<sp::Value> v(kFixedCount + sources.size());
    const rt::MachineState state = s.cycle != 0 ? s.state : rt.machine().state();
    const rt::JobProgress job = s.cycle != 0 ? s.job : rt.job().progress();
    const rt::AlarmCode cause = s.cycle != 0 ? s.cause : rt.machine().last_cause();
    v[kState] = std::string(rt::to_string(state));
    std::array<rt::ActiveAlarm, 64> latched{};
    const std::size_t n = rt.machine().active_alarms(latched.data(), latched.size());
    std::string active;
    for (std::size_t i = 0; i < n; ++i) {
      if (!active.empty()) active += ", ";
      active += std::to_string(static_cast<int>(latched[i].code)) + " " +
                std::string(rt::to_string(latched[i].code));
    }
    v[kAlarmCount] = static_cast<std::uint64_t>(n);
    v[kAlarmActive] = active;
    v[kLastCause] = cause == rt::AlarmCode::kNone ? std::string("none")
                                                  : std::to_string(static_cast<int>(cause)) + " " +
                                                        std::string(rt::to_string(cause));
    v[kJobOutcome] = std::string(rt::outcome_name(job.outcome));
    v[kJobBlock] = static_cast<std::uint64_t>(job.block_index);
    v[kJobBlocks] = static_cast<std::uint64_t>(job.block_count);
    v[kJobLine] = static_cast<std::int64_t>(job.line);
    v[kJobProgress] = job.block_count == 0 ? 0.0
                                           : 100.0 * static_cast<double>(job.block_index) /
                                                 static_cast<double>(job.block_count);
    v[kJobsStarted] = job.jobs_started;
    for (std::size_t i = 0; i < sources.size(); ++i) {
      const Source& src = sources[i];
      const sp::DataType t = node->options().device_metrics[kFixedCount + i].type;
      if (src.var->is_pin()) {
        v[kFixedCount + i] = s.cycle != 0 ? typed(t, s.pins[src.pin_index])
                                          : typed(t, rt::read_pin_as_double(src.var->pin));
      } else {
        const auto x = rt.variables().read(src.var->name);  // non-RT: the shadow copy
        v[kFixedCount + i] = x ? typed(t, *x) : sp::Value{};
      }
    }
    return v;
  }

  void run() {
    while (true) {
      step();
      std::unique_lock lock(mu);
      if (cv.wait_for(lock, cfg.interval, [this] { return stopping; })) break;
    }
    // One last look, so a state change right before the stop (e.g. the safe state) goes out.
    step();
    intake->finish(CommandIntake::Clock::now());
    node->stop();
  }

  struct Source {
    const rt::Variable* var{nullptr};
    std::size_t pin_index{0};
  };

  rt::Runtime& rt;
  MqttConfig cfg;
  CommandGate gate;
  std::vector<Source> sources;
  std::unique_ptr<SnapshotObserver> observer;
  std::unique_ptr<CommandIntake> intake;  // before node: it outlives libmosquitto's thread
  std::unique_ptr<sp::EdgeNode> node;
  std::thread thread;
  std::mutex mu;
  std::condition_variable cv;
  bool stopping{false};
};

Publisher::Publisher(rt::Runtime& runtime, MqttConfig config)
    : impl_(std::make_unique<Impl>(runtime, std::move(config))) {}

Publisher::~Publisher() { stop(); }

void Publisher::start() {
  try {
    impl_->node->start();
  } catch (const sparkplug::EdgeNodeError& e) {
    spdlog::error("{} (telemetry off; the machine runs on)", e.what());
    return;
  }
  spdlog::info("mqtt: Sparkplug B edge node {}/{} (device {}) publishing to {}:{}{}{}",
               impl_->cfg.group, impl_->cfg.node, impl_->cfg.device, impl_->cfg.host,
               impl_->cfg.port, impl_->cfg.tls ? " over TLS" : "",
               impl_->cfg.commands_enabled ? ", commands on" : "");
  impl_->thread = std::thread([this] { impl_->run(); });
}

void Publisher::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  {
    std::lock_guard lock(impl_->mu);
    impl_->stopping = true;
  }
  impl_->cv.notify_all();
  impl_->thread.join();
}

sparkplug::EdgeNodeStats Publisher::stats() const { return impl_->node->stats(); }

}  // namespace edm::telemetry
