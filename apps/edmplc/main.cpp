// edmplc — the runtime daemon: loads a machine config, runs its tasks on the real or the
// virtual clock, and on SIGINT/SIGTERM (or --run-for) stops in order: safe state, tasks joined,
// retain flushed, statistics and trace written. Exit codes: 0 ok, 1 runtime failure or alarm,
// 2 bad input. See docs/runtime.md. Under systemd it tells its readiness and feeds the watchdog
// (systemd_notify.hpp, docs/deploy.md).

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "edm/apps/cli.hpp"
#include "edm/blocks/register.hpp"
#include "edm/bridge/server.hpp"
#ifdef EDM_HAVE_HAL
#include "edm/hal/driver.hpp"
#endif
#include "edm/modbus/driver.hpp"
#include "edm/modbus/server.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/log.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/stats_json.hpp"
#include "edm/sim/sim_driver.hpp"
#include "edm/telemetry/publisher.hpp"
#include "systemd_notify.hpp"

namespace {

using edm::apps::kExitBadInput;
using edm::apps::kExitFailure;
using edm::apps::kExitOk;
using edm::apps::reject;

constexpr const char* kUsage =
    "edmplc --config FILE [--clock real|virtual [--speed F]] [--run-for DURATION]\n"
    "              [--stats-out FILE.json] [--trace-out FILE.csv] [--seed N]\n"
    "              [--bridge-port P] [--state-dir DIR] [--check] [--list-vars]\n"
    "              [--modbus-map]\n"
    "              [--log-level LEVEL]";

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int /*sig*/) { g_stop.store(true); }

struct Options {
  std::string config;
  edm::rt::ClockKind clock{edm::rt::ClockKind::kReal};
  double speed{0.0};  // --speed: paced virtual clock
  std::optional<edm::rt::Duration> run_for;
  std::string stats_out;
  std::string trace_out;
  std::optional<std::uint64_t> seed;
  std::optional<int> bridge_port;
  std::string state_dir;  // --state-dir, else $EDM_STATE_DIR: where a relative retain.file lives
  bool check{false};
  bool list_vars{false};
  bool modbus_map{false};  // print the modbus_server register map and exit
  std::string log_level{"info"};
};

std::optional<std::uint64_t> parse_u64(std::string_view s) {
  if (s.empty() || s.size() > 20) {
    return std::nullopt;
  }
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') {
      return std::nullopt;
    }
    const std::uint64_t d = static_cast<std::uint64_t>(c - '0');
    if (v > (UINT64_MAX - d) / 10) {
      return std::nullopt;
    }
    v = v * 10 + d;
  }
  return v;
}

/// The options, or the exit code when the program ends here (--help, bad arguments).
std::variant<Options, int> parse_args(int argc, char** argv) {
  Options o;
  CLI::App app(
      "the edmplc runtime: runs a machine config's tasks until SIGINT/SIGTERM or "
      "--run-for (docs/runtime.md)",
      "edmplc");
  app.add_option("--config", o.config, "the machine config (YAML)")->required();
  app.add_option_function<std::string>(
      "--clock",
      [&](const std::string& v) {
        if (v != "real" && v != "virtual") reject("--clock takes real or virtual, not '" + v + "'");
        o.clock = v == "real" ? edm::rt::ClockKind::kReal : edm::rt::ClockKind::kVirtual;
      },
      "real (default: SCHED_FIFO threads) or virtual (deterministic, fast)");
  app.add_option_function<std::string>(
      "--speed",
      [&](const std::string& v) {
        char* end = nullptr;
        o.speed = std::strtod(v.c_str(), &end);
        if (end == v.c_str() || *end != '\0' || !(o.speed > 0.0) || o.speed > 1e6) {
          reject("--speed takes a factor > 0 (virtual seconds per wall second), not '" + v + "'");
        }
      },
      "with --clock virtual: pace virtual time to F x wall time (accelerated but deterministic; "
      "an HMI can follow the job); default: unpaced");
  app.add_option_function<std::string>(
      "--run-for",
      [&](const std::string& v) {
        auto d = edm::rt::parse_duration(v);
        if (!d.value || d.value->count() == 0) {
          reject("--run-for: " + (d.value ? std::string("must be > 0") : d.error));
        }
        o.run_for = d.value;
      },
      "stop after this much (real or virtual) time, e.g. 10s; default: until SIGINT/SIGTERM");
  app.add_option("--stats-out", o.stats_out, "write per-task statistics (JSON) at exit");
  app.add_option("--trace-out", o.trace_out, "record the config's trace: variables (CSV)");
  app.add_option_function<std::string>(
      "--seed",
      [&](const std::string& v) {
        o.seed = parse_u64(v);
        if (!o.seed) reject("--seed takes an unsigned 64-bit integer, not '" + v + "'");
      },
      "override the simulator seed");
  app.add_option_function<std::string>(
      "--bridge-port",
      [&](const std::string& v) {
        const auto p = parse_u64(v);
        if (!p || *p > 65535) reject("--bridge-port takes 0..65535, not '" + v + "'");
        o.bridge_port = static_cast<int>(*p);
      },
      "override the bridge port (0 = no bridge)");
  app.add_option("--state-dir", o.state_dir,
                 "directory of a relative retain.file (default: $EDM_STATE_DIR; neither: "
                 "nothing is retained)");
  app.add_flag("--check", o.check,
               "validate the config and exit (0 ok, 2 invalid: file:line:col: message)");
  app.add_flag("--list-vars", o.list_vars,
               "print every variable (name, kind, type, unit, task; parameters also range, "
               "load-time or runtime, description) and exit");
  app.add_flag("--modbus-map", o.modbus_map,
               "print the modbus_server register map (docs/modbus.md) and exit");
  app.add_option_function<std::string>(
      "--log-level",
      [&](const std::string& v) {
        if (spdlog::level::from_str(v) == spdlog::level::off && v != "off") {
          reject("--log-level takes trace, debug, info, warn, err, critical or off");
        }
        o.log_level = v;
      },
      "trace, debug, info (default), warn, err, critical or off");
  app.callback([&] {
    if (o.speed > 0.0 && o.clock != edm::rt::ClockKind::kVirtual) {
      reject("--speed needs --clock virtual (the real clock runs at 1x)");
    }
  });
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) {
    return *code;
  }
  return o;
}

void print_diagnostics(const edm::rt::ConfigError& e) {
  for (const auto& d : e.diagnostics()) {
    std::cerr << d.str() << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = parse_args(argc, argv);
  if (const int* code = std::get_if<int>(&parsed)) {
    return *code;
  }
  const Options& opt = std::get<Options>(parsed);
  edm::rt::init_logging(spdlog::level::from_str(opt.log_level));

  edm::rt::BlockRegistry blocks;
  edm::blocks::register_builtin_blocks(blocks);
  edm::programs::register_builtin_programs(blocks);
  edm::rt::DriverRegistry drivers;
  edm::rt::register_runtime_drivers(drivers);
  edm::sim::register_sim_driver(drivers);
  edm::modbus::register_modbus_driver(drivers);
#ifdef EDM_HAVE_HAL
  // Attached only when edmplc is going to run: --check and the listings need no HAL session.
  edm::hal::register_hal_driver(drivers, !opt.check && !opt.list_vars && !opt.modbus_map);
#endif

  std::unique_ptr<edm::rt::Runtime> rt;
  // `mqtt:` (docs/mqtt.md), checked against the built runtime's variables.
  std::optional<edm::telemetry::MqttConfig> mqtt_cfg;
  std::optional<edm::modbus::ServerConfig> modbus_cfg;  // `modbus_server:` (docs/modbus.md)
  try {
    edm::rt::Config cfg = edm::rt::parse_config_file(opt.config);
    edm::rt::BuildOptions bo;
    bo.seed = opt.seed;
    bo.load_retain = !opt.check && !opt.list_vars && !opt.modbus_map;
    bo.state_dir = opt.state_dir;
    if (const char* env = std::getenv("EDM_STATE_DIR"); bo.state_dir.empty() && env != nullptr) {
      bo.state_dir = env;  // the packaging's seam (systemd StateDirectory=, docs/runtime.md)
    }
    rt = edm::rt::Runtime::build(cfg, blocks, drivers, bo);
    mqtt_cfg = edm::telemetry::load_mqtt_config(rt->config(), rt->variables());
    modbus_cfg = edm::modbus::load_server_config(rt->config(), rt->variables());
  } catch (const edm::rt::ConfigError& e) {
    edm::rt::shutdown_logging();
    print_diagnostics(e);
    return kExitBadInput;
  }

  if (opt.check) {
    // What the bridge would refuse at start (token files, bind policy, TLS files), --check
    // refuses too, at the bridge section.
    const auto& bs = rt->config().bridge;
    if (opt.bridge_port.value_or(bs.loc.line != 0 ? bs.port : 0) != 0) {
      try {
        edm::bridge::validate_options(edm::bridge::options_from_config(bs));
      } catch (const edm::bridge::BridgeError& e) {
        edm::rt::shutdown_logging();
        std::cerr << (bs.loc.file.empty() ? opt.config : bs.loc.file) << ":"
                  << std::max(bs.loc.line, 1) << ":" << std::max(bs.loc.col, 1) << ": " << e.what()
                  << "\n";
        return kExitBadInput;
      }
    }
    std::size_t n_blocks = 0;
    for (const auto& t : rt->tasks()) {
      for (const auto* p : t->programs()) {
        n_blocks += p->blocks().size();
      }
    }
    edm::rt::shutdown_logging();
    std::cout << opt.config << ": OK (" << rt->tasks().size() << " tasks, " << n_blocks
              << " blocks, " << rt->variables().all().size() << " variables)\n";
    return kExitOk;
  }
  if (opt.modbus_map) {
    edm::rt::shutdown_logging();
    if (!modbus_cfg) {
      std::cerr << opt.config << ": no modbus_server section\n";
      return kExitBadInput;
    }
    std::cout << edm::modbus::format_register_map(*modbus_cfg);
    return kExitOk;
  }
  if (opt.list_vars) {
    edm::rt::shutdown_logging();
    for (const auto& v : rt->variables().all()) {
      std::cout << edm::rt::list_row(v) << "\n";
    }
    return kExitOk;
  }
  // A field bus's image ages in wall time: faster-than-real virtual time would read it as stale
  // (alarm 121) at once. Paced at 1x or slower it runs as on the real clock.
  if (opt.clock == edm::rt::ClockKind::kVirtual && !(opt.speed > 0.0 && opt.speed <= 1.0) &&
      rt->wall_time_io()) {
    edm::rt::shutdown_logging();
    std::cerr << opt.config
              << ": its I/O driver exchanges with real devices in wall time (modbus): run it with "
                 "--clock real, or --clock virtual --speed 1 (or slower)\n";
    return kExitBadInput;
  }
  if (!rt->retain_warning().empty()) {
    spdlog::error("retain: {} (alarm retain_corrupt: the machine starts in FAULT)",
                  rt->retain_warning());
  }
  const int bridge_port =
      opt.bridge_port.value_or(rt->config().bridge.loc.line != 0 ? rt->config().bridge.port : 0);
  std::unique_ptr<edm::bridge::Server> bridge;
  if (bridge_port != 0) {
    edm::bridge::ServerOptions bo = edm::bridge::options_from_config(rt->config().bridge);
    bo.port = static_cast<std::uint16_t>(bridge_port);
    bridge = std::make_unique<edm::bridge::Server>(*rt, bo);
    try {
      bridge->start();
    } catch (const edm::bridge::BridgeError& e) {
      spdlog::error("{}", e.what());
      bridge.reset();
      rt.reset();
      edm::rt::shutdown_logging();
      return kExitBadInput;
    }
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::unique_ptr<edm::modbus::Server> modbus_server;  // its own thread, never the RT ones
  if (modbus_cfg) {
    modbus_server = std::make_unique<edm::modbus::Server>(rt->variables(), *modbus_cfg);
    try {
      modbus_server->start();
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      modbus_server.reset();
      if (bridge) {
        bridge->stop();
        bridge.reset();
      }
      rt.reset();
      edm::rt::shutdown_logging();
      return kExitBadInput;
    }
  }
  std::unique_ptr<edm::telemetry::Publisher> mqtt;  // its own thread, never the RT ones
  if (mqtt_cfg) (mqtt = std::make_unique<edm::telemetry::Publisher>(*rt, *mqtt_cfg))->start();

  edm::rt::RunOptions ro;
  ro.speed = opt.speed;
  ro.clock = opt.clock;
  ro.run_for = opt.run_for;
  ro.stop = &g_stop;
  ro.trace_out = opt.trace_out;
  int code = kExitOk;
  edmplc::SystemdNotifier notifier(*rt, g_stop);
  notifier.start();  // READY=1 once every task cycles, then WATCHDOG=1: off the RT threads
  spdlog::info("running {} task(s) on the {} clock{}", rt->tasks().size(),
               opt.clock == edm::rt::ClockKind::kReal ? "real" : "virtual",
               opt.run_for ? " for " + edm::rt::format_duration(*opt.run_for) : "");
  try {
    const edm::rt::RunSummary s = rt->run(ro);
    if (s.trace_dropped > 0) {
      spdlog::warn("trace: {} samples dropped (the writer could not keep up)", s.trace_dropped);
    }
    if (edm::rt::is_safe_state(s.final_state)) {
      spdlog::error("stopped in {} (see alarms above)", to_string(s.final_state));
      code = kExitFailure;
    }
    if (!opt.stats_out.empty()) {
      edm::rt::write_stats_json_file(opt.stats_out, rt->stats_reports());
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    code = kExitFailure;
  }
  notifier.stop();
  // DDEATH + NDEATH with the final state, before the runtime goes.
  mqtt.reset();
  modbus_server.reset();  // before the runtime goes: it reads and writes its registry
  if (bridge) {
    bridge->stop();  // before the runtime goes: the server reads its machine, job and registry
    bridge.reset();
  }
  rt.reset();
  edm::rt::shutdown_logging();
  return code;
}
