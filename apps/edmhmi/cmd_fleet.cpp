#include "cmd_fleet.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "cli.hpp"
#include "edm/sparkplug/fleet.hpp"

namespace edmhmi {

void add_fleet_command(CLI::App& app, FleetArgs& a) {
  CLI::App* f = app.add_subcommand(
      "fleet", "every machine on an MQTT broker (Sparkplug B): state, job, alarms (docs/mqtt.md)");
  f->add_option("--broker", a.broker, "the broker, HOST:PORT")->required();
  f->add_option("--group", a.group, "only this Sparkplug group (default: every group)");
  f->add_flag("--watch", a.watch, "refresh until Ctrl-C (default: print once)");
  f->add_flag("--json", a.json, "print JSON (an array, one object per machine)");
  f->add_option("--wait", a.wait_s, "once: listen this many seconds first (default 3)")
      ->check(CLI::Range(0.1, 600.0));
  f->add_option("--refresh", a.refresh_s, "--watch: reprint every this many seconds (default 1)")
      ->check(CLI::Range(0.1, 600.0));
  f->add_option("--username", a.username, "the broker's user name");
  f->add_option("--password-file", a.password_file, "the broker's password, first line");
  f->add_option("--tls-ca", a.tls_ca, "TLS: the broker verified by this CA file");
  f->add_flag("--no-rebirth", a.no_rebirth,
              "never ask a node for its births (NCMD Node Control/Rebirth)");
}

int cmd_fleet(const FleetArgs& a) {
  namespace sp = edm::sparkplug;
  sp::FleetOptions o;
  const auto colon = a.broker.rfind(':');
  int port = 0;
  if (colon != std::string::npos && colon > 0) {
    try {
      port = std::stoi(a.broker.substr(colon + 1));
    } catch (const std::exception&) {
      port = 0;
    }
  }
  if (port < 1 || port > 65535) return usage("--broker takes HOST:PORT, not '" + a.broker + "'");
  o.host = a.broker.substr(0, colon);
  o.port = port;
  o.group = a.group;
  o.username = a.username;
  o.ask_rebirth = !a.no_rebirth;
  if (!a.password_file.empty()) {
    std::ifstream in(a.password_file);
    if (!in || !std::getline(in, o.password)) {
      return usage("cannot read --password-file '" + a.password_file + "'");
    }
  }
  if (!a.tls_ca.empty()) o.tls = sp::TlsOptions{a.tls_ca, "", "", true};

  sp::FleetWatcher watcher(o);
  try {
    watcher.start();
  } catch (const sp::EdgeNodeError& e) {
    std::fprintf(stderr, "edmhmi: fleet: %s\n", e.what());
    return kExitFailure;
  }
  install_signal_handlers();
  using clock = std::chrono::steady_clock;
  const auto print = [&] {
    const auto machines = watcher.machines();
    const std::string out =
        a.json ? sp::render_json(machines, sp::now_ms()) : sp::render_text(machines, sp::now_ms());
    if (a.watch && !a.json && ::isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
    std::fputs(out.c_str(), stdout);
    if (a.watch && !a.json) std::fputs("\n", stdout);
    std::fflush(stdout);
  };
  const auto step = std::chrono::milliseconds(50);
  auto next = clock::now() + std::chrono::duration_cast<clock::duration>(
                                 std::chrono::duration<double>(a.watch ? 0.5 : a.wait_s));
  while (!interrupted().load()) {
    watcher.poll();
    if (clock::now() >= next) {
      print();
      if (!a.watch) return kExitOk;
      next = clock::now() + std::chrono::duration_cast<clock::duration>(
                                std::chrono::duration<double>(a.refresh_s));
    }
    std::this_thread::sleep_for(step);
  }
  return a.watch ? kExitOk : kExitInterrupted;
}

}  // namespace edmhmi
