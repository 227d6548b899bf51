// edmhmi — the HMI process's command line (DESIGN §4, docs/hmi.md). One file per command group:
// cmd_check.cpp (offline interpretation), cmd_run.cpp (upload, start, follow, report),
// cmd_status.cpp (status, stats), cmd_machine.cpp (hold, resume, stop, estop, reset),
// cmd_watch.cpp (watch, trace). Exit codes: 0 ok, 1 runtime failure or alarm, 2 bad input.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "cli.hpp"

namespace edmhmi {

namespace {

constexpr const char* kUsage =
    "usage: edmhmi [--host H] [--port P] [--token-file F] [--tls-ca F | --tls-fingerprint FP]\n"
    "              COMMAND ...\n"
    "  connection: --host (else $EDM_HOST, 127.0.0.1), --port (else $EDM_PORT, 7730),\n"
    "              --token-file (else $EDM_TOKEN_FILE, else the token in $EDM_TOKEN),\n"
    "              TLS verified by --tls-ca (else $EDM_TLS_CA) or the server certificate's\n"
    "              SHA-256 --tls-fingerprint (else $EDM_TLS_FINGERPRINT)\n"
    "commands:\n"
    "  check [--machine CONFIG] PART.nc   interpret offline against CONFIG (default\n"
    "                                     config/machines/drill-sim.yaml); nothing is sent\n"
    "  run [--detach] [--quiet] PART.nc   upload, start, show progress, print the job report;\n"
    "                                     exit 1 when the job does not finish or an alarm came\n"
    "  status                             machine state, job, key variables, last job's figures\n"
    "  watch [--rate HZ] [--count N] VAR...     print variables until Ctrl-C (or N samples)\n"
    "  trace VAR... --out FILE.csv [--duration S]  record every cycle of VAR... to CSV\n"
    "  stats                              task statistics and bridge counters\n"
    "  hold | resume | stop | estop | reset   machine commands\n"
    "  serve [--listen HOST:PORT] [--web-root DIR]  the operator's page in a browser (default\n"
    "                                     127.0.0.1:8080; docs/web.md)\n";

std::atomic<bool> g_interrupted{false};

extern "C" void on_signal(int /*sig*/) { g_interrupted.store(true); }

int run(int argc, char** argv) {
  const Args args(argv + 1, argv + argc);
  edm::hmi::ConnectionFlags flags;
  std::size_t i = 0;
  while (i < args.size() && args[i].starts_with("--")) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    }
    std::string* target = args[i] == "--host"              ? &flags.host
                          : args[i] == "--port"            ? &flags.port
                          : args[i] == "--token-file"      ? &flags.token_file
                          : args[i] == "--tls-ca"          ? &flags.tls_ca_file
                          : args[i] == "--tls-fingerprint" ? &flags.tls_fingerprint
                                                           : nullptr;
    if (target == nullptr) return usage("unknown option '" + std::string(args[i]) + "'");
    if (i + 1 >= args.size()) return usage(std::string(args[i]) + " needs a value");
    *target = std::string(args[i + 1]);
    i += 2;
  }
  if (i >= args.size()) return usage("missing command");
  const std::string_view command = args[i];
  const Args rest(args.begin() + static_cast<std::ptrdiff_t>(i) + 1, args.end());
  if (command == "check") return cmd_check(rest);

  edm::hmi::ConnectionSettings settings;
  try {
    settings = edm::hmi::resolve_connection(
        flags, [](const char* n) -> const char* { return std::getenv(n); });
  } catch (const edm::hmi::SettingsError& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return kExitBadInput;
  }
  install_signal_handlers();
  if (command == "run") return cmd_run(rest, settings);
  if (command == "status") return cmd_status(rest, settings);
  if (command == "stats") return cmd_stats(rest, settings);
  if (command == "watch") return cmd_watch(rest, settings);
  if (command == "trace") return cmd_trace(rest, settings);
  if (command == "serve") return cmd_serve(rest, settings);
  for (std::string_view c : {"hold", "resume", "stop", "estop", "reset"}) {
    if (command == c) return cmd_machine(command, rest, settings);
  }
  return usage("unknown command '" + std::string(command) + "'");
}

}  // namespace

std::atomic<bool>& interrupted() { return g_interrupted; }

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int usage(const std::string& message) {
  std::fprintf(stderr, "edmhmi: %s\n%s", message.c_str(), kUsage);
  return kExitBadInput;
}

}  // namespace edmhmi

int main(int argc, char** argv) {
  try {
    return edmhmi::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return edmhmi::kExitFailure;
  }
}
