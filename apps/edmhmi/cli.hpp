#pragma once
// What every edmhmi command shares: exit codes, the connection to edmplc, the interrupt flag.
// (DESIGN §4: exit 0 ok, 1 runtime failure or alarm, 2 bad input.)

#include <atomic>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/bridge/client.hpp"
#include "edm/hmi/connection.hpp"
#include "edm/hmi/job_runner.hpp"

namespace edmhmi {

using edm::apps::kExitBadInput;
using edm::apps::kExitFailure;
using edm::apps::kExitOk;
inline constexpr int kExitInterrupted = 130;

/// The arguments of each command, filled by CLI11 in main.cpp.
struct CheckArgs {
  std::string machine;  // --machine; "" = machines/drill-sim.yaml of the data directory
  std::string offsets;  // --offsets FILE: the work frames as offset.get returns them; "" = zero
  std::string part;
};
struct RunArgs {
  bool detach{false};
  bool quiet{false};
  bool dry_run{false};
  int from_line{0};                  // --from N: resume at source line N (0: from the start)
  std::optional<double> depth_done;  // --depth-done MM
  std::string part;
};
struct HomeArgs {
  std::string axes;  // "" = every axis
};
struct JogArgs {
  std::string axis;
  std::optional<double> distance;  // incremental, mm
  std::optional<double> velocity;  // continuous, mm/s
  double for_s{0.0};               // continuous: seconds (0: until Ctrl-C)
};
struct TouchArgs {
  std::string target;
  std::string set_frame;  // --set G54..G59: the result goes into this frame
};
struct OffsetArgs {
  std::vector<std::string> words;  // [G54..G59] [X.. Y.. Z..]
  bool json{false};
};
struct WatchArgs {
  double rate_hz{5.0};
  double count{0.0};  // 0: until Ctrl-C
  std::vector<std::string> names;
};
struct TraceArgs {
  std::string out_path;
  double duration_s{0.0};  // 0: until Ctrl-C
  std::vector<std::string> names;
};
struct ServeArgs {
  std::string listen{"127.0.0.1:8080"};
  std::string web_root;       // --web-root; "" = web/ of the data directory (data_dir.hpp)
  bool insecure{false};       // --insecure-listen: plain HTTP off loopback (bridge without TLS)
  std::string tls_cert;       // --tls-cert, else $EDM_WEB_TLS_CERT: HTTPS when set (with the key)
  std::string tls_key;        // --tls-key, else $EDM_WEB_TLS_KEY
  bool insecure_http{false};  // --insecure-http: plain HTTP anywhere, even when the bridge is TLS
  std::vector<std::string> allow_hosts;  // --allow-host NAME[:PORT] (+ $EDM_WEB_ALLOW_HOSTS)
};

/// Set by SIGINT / SIGTERM; loops poll it.
std::atomic<bool>& interrupted();
void install_signal_handlers();

/// "edmhmi: message" + the usage line on stderr (a bad argument CLI11 could not see); returns
/// kExitBadInput.
int usage(const std::string& message);

/// Connects and says hello; prints why on failure and returns false.
bool connect(edm::bridge::Client& client, const edm::hmi::ConnectionSettings& settings,
             bool auto_reconnect = false);

/// Runs one of edm::hmi's fetch_* calls (they throw bridge::ClientError when a request is
/// refused or its reply malformed); prints why it failed and returns nullopt.
template <class Fetch>
auto fetch(Fetch&& f) -> std::optional<decltype(f())> {
  try {
    return f();
  } catch (const edm::bridge::ClientError& e) {
    std::fprintf(stderr, "edmhmi: %s\n", e.what());
    return std::nullopt;
  }
}

/// Connects, reconnecting while a job runs, and fetches the machine a program is interpreted
/// against (tables, work frames, where the electrode is); prints why on failure and returns
/// nullopt.
std::optional<edm::hmi::MachineView> connect_and_fetch_machine(
    edm::bridge::Client& client, const edm::hmi::ConnectionSettings& settings);

/// Prints a refused reply ("edmhmi: op: code: message") and returns the exit code for it.
int report_error(std::string_view op, const edm::bridge::Reply& reply);

/// Reads a whole text file (at most 64 MiB); prints why on failure and returns false.
bool read_text_file(const std::string& path, std::string& out);

int cmd_check(const CheckArgs& args);
int cmd_run(const RunArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_status(const edm::hmi::ConnectionSettings& settings);
int cmd_stats(const edm::hmi::ConnectionSettings& settings);
int cmd_machine(std::string_view command, const edm::hmi::ConnectionSettings& settings);
int cmd_override(double percent, const edm::hmi::ConnectionSettings& settings);
int cmd_home(const HomeArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_jog(const JogArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_touch(const TouchArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_offset(const OffsetArgs& args, const edm::hmi::ConnectionSettings& settings);
struct ElectrodeArgs {
  std::string action;  // "" (print), set, change, measure
  double length_mm{0.0};
  std::string id, kind, material;
  double size_mm{0.0}, new_length_mm{0.0};
  std::string reference;  // measure: setter, work
  std::string frame;      // measure work: G54 … G59 ("" = G54)
};
/// `edmhmi electrode [set MM | change ID … | measure setter|work]` (cmd_electrode.cpp).
int cmd_electrode(const ElectrodeArgs& args, const edm::hmi::ConnectionSettings& settings);
/// `edmhmi alarms [--all]`: the active alarms with cause and remedy; --all adds the history.
int cmd_alarms(bool all, const edm::hmi::ConnectionSettings& settings);
/// `edmhmi jobs [--csv] [--limit N]`: the job log, newest last.
int cmd_jobs(bool csv, int limit, const edm::hmi::ConnectionSettings& settings);
/// Prints the active alarms as `alarms` does (status); false, and why, when they cannot be read.
bool print_active_alarms(edm::bridge::Client& client);
/// `edmhmi queue PART.nc[*N] …` (cmd_queue.cpp).
int cmd_queue(const std::vector<std::string>& words, const edm::hmi::ConnectionSettings& settings);
int cmd_mdi(const std::string& line, const edm::hmi::ConnectionSettings& settings);
int cmd_watch(const WatchArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_trace(const TraceArgs& args, const edm::hmi::ConnectionSettings& settings);
int cmd_serve(const ServeArgs& args, const edm::hmi::ConnectionSettings& settings);

}  // namespace edmhmi
