// edmplc — the runtime daemon: loads a machine config, runs its tasks on the real or the
// virtual clock, and on SIGINT/SIGTERM (or --run-for) stops in order: safe state, tasks joined,
// retain flushed, statistics and trace written. Exit codes: 0 ok, 1 runtime failure or alarm,
// 2 bad input. See docs/runtime.md.

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

#include "edm/blocks/register.hpp"
#include "edm/bridge/server.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/log.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/stats_json.hpp"
#include "edm/sim/sim_driver.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

constexpr std::string_view kUsage =
    "usage: edmplc --config FILE [--clock real|virtual [--speed F]] [--run-for DURATION]\n"
    "              [--stats-out FILE.json] [--trace-out FILE.csv] [--seed N]\n"
    "              [--bridge-port P] [--check] [--list-vars] [--log-level LEVEL]\n"
    "  --check       validate the config and exit (0 ok, 2 invalid: file:line:col: message)\n"
    "  --list-vars   print every variable (name, kind, type, unit, task) and exit\n"
    "  --run-for     stop after this much (real or virtual) time, e.g. 10s; default: until\n"
    "                SIGINT/SIGTERM\n"
    "  --clock       real (default: SCHED_FIFO threads) or virtual (deterministic, fast)\n"
    "  --speed F     with --clock virtual: pace virtual time to F x wall time (accelerated\n"
    "                but deterministic; an HMI can follow the job); default: unpaced\n";

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
  bool check{false};
  bool list_vars{false};
  std::string log_level{"info"};
};

[[noreturn]] void bad_usage(const std::string& message) {
  std::cerr << "edmplc: " << message << "\n" << kUsage;
  std::exit(kExitBadInput);
}

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

Options parse_args(int argc, char** argv) {
  Options o;
  auto value = [&](int& i, std::string_view flag) -> std::string {
    if (i + 1 >= argc) {
      bad_usage(std::string(flag) + " needs a value");
    }
    return argv[++i];
  };
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--config") {
      o.config = value(i, a);
    } else if (a == "--clock") {
      const std::string v = value(i, a);
      if (v == "real") {
        o.clock = edm::rt::ClockKind::kReal;
      } else if (v == "virtual") {
        o.clock = edm::rt::ClockKind::kVirtual;
      } else {
        bad_usage("--clock takes real or virtual, not '" + v + "'");
      }
    } else if (a == "--speed") {
      const std::string v = value(i, a);
      char* end = nullptr;
      o.speed = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !(o.speed > 0.0) || o.speed > 1e6) {
        bad_usage("--speed takes a factor > 0 (virtual seconds per wall second), not '" + v + "'");
      }
    } else if (a == "--run-for") {
      const std::string v = value(i, a);
      auto d = edm::rt::parse_duration(v);
      if (!d.value || d.value->count() == 0) {
        bad_usage("--run-for: " + (d.value ? std::string("must be > 0") : d.error));
      }
      o.run_for = d.value;
    } else if (a == "--stats-out") {
      o.stats_out = value(i, a);
    } else if (a == "--trace-out") {
      o.trace_out = value(i, a);
    } else if (a == "--seed") {
      const std::string v = value(i, a);
      o.seed = parse_u64(v);
      if (!o.seed) {
        bad_usage("--seed takes an unsigned 64-bit integer, not '" + v + "'");
      }
    } else if (a == "--bridge-port") {
      const std::string v = value(i, a);
      auto p = parse_u64(v);
      if (!p || *p > 65535) {
        bad_usage("--bridge-port takes 0..65535, not '" + v + "'");
      }
      o.bridge_port = static_cast<int>(*p);
    } else if (a == "--check") {
      o.check = true;
    } else if (a == "--list-vars") {
      o.list_vars = true;
    } else if (a == "--log-level") {
      o.log_level = value(i, a);
      if (spdlog::level::from_str(o.log_level) == spdlog::level::off && o.log_level != "off") {
        bad_usage("--log-level takes trace, debug, info, warn, err, critical or off");
      }
    } else if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      std::exit(kExitOk);
    } else {
      bad_usage("unknown argument '" + std::string(a) + "'");
    }
  }
  if (o.config.empty()) {
    bad_usage("--config FILE is required");
  }
  if (o.speed > 0.0 && o.clock != edm::rt::ClockKind::kVirtual) {
    bad_usage("--speed needs --clock virtual (the real clock runs at 1x)");
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
  const Options opt = parse_args(argc, argv);
  edm::rt::init_logging(spdlog::level::from_str(opt.log_level));

  edm::rt::BlockRegistry blocks;
  edm::blocks::register_builtin_blocks(blocks);
  edm::programs::register_builtin_programs(blocks);
  edm::rt::DriverRegistry drivers;
  edm::rt::register_runtime_drivers(drivers);
  edm::sim::register_sim_driver(drivers);

  std::unique_ptr<edm::rt::Runtime> rt;
  try {
    edm::rt::Config cfg = edm::rt::parse_config_file(opt.config);
    edm::rt::BuildOptions bo;
    bo.seed = opt.seed;
    bo.load_retain = !opt.check && !opt.list_vars;
    rt = edm::rt::Runtime::build(cfg, blocks, drivers, bo);
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
  if (opt.list_vars) {
    edm::rt::shutdown_logging();
    for (const auto& v : rt->variables().all()) {
      std::cout << v.name << "\t" << to_string(v.kind) << "\t" << v.type_name() << "\t"
                << (v.unit.empty() ? "-" : v.unit) << "\t"
                << (v.owner != nullptr ? v.owner->name() : "-") << "\n";
    }
    return kExitOk;
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

  edm::rt::RunOptions ro;
  ro.speed = opt.speed;
  ro.clock = opt.clock;
  ro.run_for = opt.run_for;
  ro.stop = &g_stop;
  ro.trace_out = opt.trace_out;
  int code = kExitOk;
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
  if (bridge) {
    bridge->stop();  // before the runtime goes: the server reads its machine, job and registry
    bridge.reset();
  }
  rt.reset();
  edm::rt::shutdown_logging();
  return code;
}
