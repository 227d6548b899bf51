// edmhmi — the HMI process's command line (DESIGN §4, docs/hmi.md). One file per command group:
// cmd_check.cpp (offline interpretation), cmd_run.cpp (upload, start, follow, report),
// cmd_status.cpp (status, stats), cmd_alarms.cpp (alarms), cmd_jobs.cpp (jobs), cmd_machine.cpp
// (hold, resume, stop, estop, reset, override), cmd_manual.cpp (home, jog, touch), cmd_offset.cpp
// (offset), cmd_mdi.cpp (mdi), cmd_watch.cpp (watch, trace). Exit codes: 0 ok, 1 runtime failure or
// alarm, 2 bad input.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "cmd_fleet.hpp"
#include "data_dir.hpp"

namespace edmhmi {

namespace {

constexpr const char* kUsage =
    "edmhmi [--host H] [--port P] [--token-file F] [--tls-ca F | --tls-fingerprint FP] "
    "COMMAND ... (edmhmi --help: the commands)";

std::atomic<bool> g_interrupted{false};

extern "C" void on_signal(int /*sig*/) { g_interrupted.store(true); }

int run(int argc, char** argv) {
  CLI::App app(
      "edmhmi: the HMI of edmplc (docs/hmi.md). Exit 0 ok, 1 runtime failure or alarm, "
      "2 bad input.",
      "edmhmi");
  app.require_subcommand(1);
  edm::hmi::ConnectionFlags flags;
  app.add_option("--host", flags.host, "edmplc's host (else $EDM_HOST, else 127.0.0.1)");
  app.add_option("--port", flags.port, "its bridge port (else $EDM_PORT, else 7730)");
  app.add_option("--token-file", flags.token_file,
                 "the token's file (else $EDM_TOKEN_FILE, else the token in $EDM_TOKEN)");
  app.add_option("--tls-ca", flags.tls_ca_file,
                 "TLS, the server verified by this CA file (else $EDM_TLS_CA)");
  app.add_option("--tls-fingerprint", flags.tls_fingerprint,
                 "TLS, the server certificate's SHA-256 pinned (else $EDM_TLS_FINGERPRINT)");
  std::string data_dir;
  app.add_option("--data-dir", data_dir,
                 "the shipped machines/ and web/ (else $EDM_DATA_DIR, else ../share/edmplc "
                 "beside this program, else the build tree it runs from)");

  CheckArgs check;
  CLI::App* c = app.add_subcommand("check",
                                   "interpret PART.nc offline against a machine's "
                                   "conditions and soft limits; nothing is sent");
  c->add_option("--machine", check.machine,
                "the machine config (default: machines/drill-sim.yaml of the data directory)");
  c->add_option("--offsets", check.offsets,
                "the work frames G54..G59 as JSON, as `edmhmi offset --json` prints them "
                "(default: all zero)");
  c->add_option("PART.nc", check.part, "the part program")->required();

  RunArgs run;
  CLI::App* r = app.add_subcommand(
      "run",
      "upload PART.nc, start it, show progress, print the job report; exit 1 when the job does "
      "not finish or an alarm came");
  r->add_flag("--detach", run.detach, "return once the job has started");
  r->add_flag("--quiet", run.quiet, "no progress, only the report");
  r->add_flag("--dry-run", run.dry_run,
              "the motion with the generator off: drilling and orbit blocks are skipped");
  r->add_option("--from", run.from_line,
                "resume at source line N (the first block whose line is >= N), after a safe "
                "re-approach")
      ->check(CLI::PositiveNumber);
  r->add_option("--depth-done", run.depth_done,
                "with --from at a drilling line: the depth the hole already has, mm (default: "
                "the runtime's record of the interrupted job)")
      ->check(edm::apps::kFinite);
  r->add_option("PART.nc", run.part, "the part program")->required();

  app.add_subcommand("status", "machine state, job, key variables, last job's figures");
  app.add_subcommand("stats", "task statistics and bridge counters");
  bool jobs_csv = false;
  int jobs_limit = 50;
  CLI::App* jb = app.add_subcommand("jobs", "the job log: each job that ended, with its figures");
  jb->add_flag("--csv", jobs_csv, "the whole log as CSV");
  jb->add_option("--limit", jobs_limit, "the newest N jobs (1..1000, default 50)")
      ->check(CLI::Range(1, 1000));
  bool alarms_all = false;
  app.add_subcommand("alarms", "the active alarms with their cause and remedy")
      ->add_flag("--all", alarms_all, "also the history since edmplc started");

  WatchArgs watch;
  CLI::App* w = app.add_subcommand("watch", "print variables until Ctrl-C (or N samples)");
  w->add_option("--rate", watch.rate_hz, "samples per second, at most 100")
      ->check(edm::apps::kPositive)
      ->check(CLI::Validator(
          [](const std::string& v) {
            return std::stod(v) <= 100.0 ? std::string() : "at most 100 Hz, not " + v;
          },
          ""))
      ->capture_default_str();
  w->add_option("--count", watch.count, "stop after N samples")->check(edm::apps::kPositive);
  w->add_option("VAR", watch.names, "variables")->required();

  TraceArgs trace;
  CLI::App* t = app.add_subcommand("trace", "record every cycle of VAR... to CSV");
  t->add_option("--out", trace.out_path, "the CSV file")->required();
  t->add_option("--duration", trace.duration_s, "seconds (default: until Ctrl-C)")
      ->check(edm::apps::kPositive);
  t->add_option("VAR", trace.names, "variables")->required();

  for (const char* m : {"hold", "resume", "stop", "estop", "reset"}) {
    app.add_subcommand(m, "machine command");
  }
  double override_pct = 100.0;
  CLI::App* ov = app.add_subcommand("override", "feed override, 0 to 150 % (operator)");
  ov->add_option("PERCENT", override_pct, "percent of the programmed feed")
      ->required()
      ->check(CLI::Range(0.0, 150.0));

  HomeArgs home;
  CLI::App* h = app.add_subcommand("home", "reference the axes (all, or e.g. Z or XY)");
  h->add_option("AXES", home.axes, "some of X, Y, Z (default: every axis)");

  JogArgs jog;
  CLI::App* j = app.add_subcommand(
      "jog", "move one axis: DIST mm (incremental), or --velocity V mm/s while held");
  j->add_option("AXIS", jog.axis, "X, Y or Z")->required();
  j->add_option("DIST", jog.distance, "mm, 0.001..10 in magnitude; the sign is the direction")
      ->check(edm::apps::kFinite);
  j->add_option("--velocity", jog.velocity, "mm/s; the sign is the direction")
      ->check(edm::apps::kFinite);
  j->add_option("--for", jog.for_s, "with --velocity: seconds (default: until Ctrl-C)")
      ->check(edm::apps::kPositive);

  TouchArgs touch;
  CLI::App* tc =
      app.add_subcommand("touch", "touch off by electrical contact: z, x+, x-, y+, y- or center");
  tc->add_option("TARGET", touch.target, "z | x+ | x- | y+ | y- | center")->required();
  tc->add_option("--set", touch.set_frame, "put the result into this work frame (G54..G59)");

  OffsetArgs offset;
  CLI::App* of = app.add_subcommand(
      "offset", "print the work frames, or set one: offset G54 X12.5 Y-3 Z-41.25");
  of->add_option("WORDS", offset.words, "[G54..G59] [X<mm>] [Y<mm>] [Z<mm>]");
  of->add_flag("--json", offset.json, "print the frames as JSON (for check --offsets)");

  std::vector<std::string> electrode_words;
  ElectrodeArgs electrode;
  CLI::App* el = app.add_subcommand(
      "electrode",
      "the electrode and the electrode table: electrode | electrode set 300 | electrode change "
      "E2 --kind tube --size 1 --material copper --new-length 300 | electrode measure setter");
  el->add_option("WORDS", electrode_words, "[set <mm> | change <id> | measure setter|work]");
  el->add_option("--kind", electrode.kind, "change: round, tube or rect");
  el->add_option("--size", electrode.size_mm, "change: diameter or width [mm]");
  el->add_option("--material", electrode.material, "change: copper, graphite, CuW, …");
  el->add_option("--new-length", electrode.new_length_mm, "change: its length when new [mm]");
  el->add_option("--frame", electrode.frame, "measure work: the frame whose Z is the surface");

  std::vector<std::string> queue_words;
  app.add_subcommand("queue",
                     "run part programs one after the other, PART.nc*N N times; stop before a "
                     "hole the electrode cannot finish, go on once it is changed and measured")
      ->add_option("PARTS", queue_words,
                   "PART.nc, PART.nc*N or PART.nc*N@DX,DY (each run DX,DY mm further), in order")
      ->required();

  std::string mdi_line;
  CLI::App* md = app.add_subcommand("mdi", "run one G-code line from where the electrode is");
  md->add_option("LINE", mdi_line, "the G-code line, quoted")->required();

  ServeArgs serve;
  CLI::App* s = app.add_subcommand("serve", "the operator's page in a browser (docs/web.md)");
  s->add_option("--listen", serve.listen, "HOST:PORT")->capture_default_str();
  s->add_option("--web-root", serve.web_root,
                "the built page (default: web/ of the data directory)");
  s->add_flag("--insecure-listen", serve.insecure,
              "allow a non-loopback address (plain HTTP: tokens in clear)");
  s->add_option("--tls-cert", serve.tls_cert,
                "serve HTTPS/WSS with this PEM certificate chain (else $EDM_WEB_TLS_CERT)");
  s->add_option("--tls-key", serve.tls_key,
                "the PEM private key of --tls-cert (else $EDM_WEB_TLS_KEY)");
  s->add_flag("--insecure-http", serve.insecure_http,
              "allow plain HTTP on any address even when the bridge uses TLS (tokens in clear)");
  s->add_option("--allow-host", serve.allow_hosts,
                "a name the page is reached by, NAME or NAME:PORT (repeatable; also "
                "$EDM_WEB_ALLOW_HOSTS)");

  FleetArgs fleet;
  add_fleet_command(app, fleet);

  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) return *code;
  const std::string command = app.get_subcommands().front()->get_name();
  if (command == "fleet") return cmd_fleet(fleet);  // MQTT, not the bridge (docs/mqtt.md)
  if ((command == "check" && check.machine.empty()) ||
      (command == "serve" && serve.web_root.empty())) {
    const DataPaths data = find_data_paths(data_dir, std::getenv("EDM_DATA_DIR"), self_exe());
    if (data.config_dir.empty()) {
      return usage(command == "check" ? "no machine config: pass --machine, or --data-dir"
                                      : "no built page: pass --web-root, or --data-dir");
    }
    if (command == "check") {
      check.machine = (data.config_dir / kDefaultMachine).string();
    } else {
      serve.web_root = data.web_root.string();
    }
  }
  if (command == "check") return cmd_check(check);

  edm::hmi::ConnectionSettings settings;
  try {
    settings = edm::hmi::resolve_connection(
        flags, [](const char* n) -> const char* { return std::getenv(n); });
  } catch (const edm::hmi::SettingsError& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return kExitBadInput;
  }
  install_signal_handlers();
  if (command == "run") return cmd_run(run, settings);
  if (command == "status") return cmd_status(settings);
  if (command == "stats") return cmd_stats(settings);
  if (command == "alarms") return cmd_alarms(alarms_all, settings);
  if (command == "jobs") return cmd_jobs(jobs_csv, jobs_csv ? 1000 : jobs_limit, settings);
  if (command == "watch") return cmd_watch(watch, settings);
  if (command == "trace") return cmd_trace(trace, settings);
  if (command == "serve") {
    for (auto [value, name] : {std::pair{&serve.tls_cert, "EDM_WEB_TLS_CERT"},
                               std::pair{&serve.tls_key, "EDM_WEB_TLS_KEY"}}) {
      const char* env = std::getenv(name);
      if (value->empty() && env != nullptr) *value = env;
    }
    return cmd_serve(serve, settings);
  }
  if (command == "override") return cmd_override(override_pct, settings);
  if (command == "home") return cmd_home(home, settings);
  if (command == "jog") return cmd_jog(jog, settings);
  if (command == "touch") return cmd_touch(touch, settings);
  if (command == "offset") return cmd_offset(offset, settings);
  if (command == "electrode") {
    const auto& ew = electrode_words;
    if (!ew.empty()) electrode.action = ew[0];
    if (ew.empty()) return cmd_electrode(electrode, settings);
    if (ew[0] == "set") {
      const std::optional<double> mm =
          ew.size() == 2 ? edm::apps::finite_number(ew[1]) : std::nullopt;
      if (!mm || *mm <= 0.0) return usage("electrode set: expected `electrode set <mm>` (mm > 0)");
      electrode.length_mm = *mm;
      return cmd_electrode(electrode, settings);
    }
    if (ew[0] == "change" && ew.size() == 2) {
      electrode.id = ew[1];
      return cmd_electrode(electrode, settings);
    }
    if (ew[0] == "measure" && ew.size() == 2 && (ew[1] == "setter" || ew[1] == "work")) {
      electrode.reference = ew[1];
      return cmd_electrode(electrode, settings);
    }
    return usage(
        "electrode: expected `electrode`, `electrode set <mm>`, `electrode change <id> [--kind "
        "K --size MM --material M --new-length MM]` or `electrode measure setter|work`");
  }
  if (command == "mdi") return cmd_mdi(mdi_line, settings);
  if (command == "queue") return cmd_queue(queue_words, settings);
  return cmd_machine(command, settings);
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
  std::fprintf(stderr, "edmhmi: %s\nusage: %s\n", message.c_str(), kUsage);
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
