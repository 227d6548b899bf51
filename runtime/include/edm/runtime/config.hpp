#pragma once
// The configuration document (YAML, version 1) as plain structs, before any block is built.
// parse_config_file() checks structure, keys, types and ranges of everything it can check
// without the block registry; build_runtime() (runtime.hpp) checks block types, parameters and
// wires. Both report every problem as file:line:col. docs/config.md is the user-facing schema.
// Non-RT; thread-compatible.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/time.hpp"

namespace edm::rt {

/// A name written in the config, with where it was written.
struct NameRef {
  std::string name;
  SourceLoc loc;
};

/// One `key: value` under a `params:` map. Values are scalars, kept as written; the builder
/// converts them to the parameter's type (and reports type errors at value_loc).
struct ParamSetting {
  std::string key;
  std::string value;   // the scalar's text
  bool quoted{false};  // the scalar was quoted ("1.0" is then a string, not a number)
  SourceLoc key_loc;
  SourceLoc value_loc;
};

struct BlockSpec {
  std::string name;
  std::string type;
  std::vector<ParamSetting> params;
  SourceLoc loc;       // the block entry
  SourceLoc name_loc;  // the name's value
  SourceLoc type_loc;  // the type's value
};

/// `dest: source` under `wires:`. dest is `block.pin` or `io.pin` (an input); source is
/// `block.pin`, `program.block.pin` or `io.pin` (an output), or a constant.
struct WireSpec {
  std::string dest;
  std::string source;         // text of the scalar
  bool source_is_name{true};  // false: a constant (number or true/false)
  SourceLoc dest_loc;
  SourceLoc source_loc;
};

/// A program's blocks and wires are its own followed by those of the fragments it includes
/// (`include:`, docs/config.md "Fragments"), in include order; each keeps its own file's location.
struct ProgramSpec {
  std::string name;
  std::vector<BlockSpec> blocks;
  std::vector<WireSpec> wires;
  SourceLoc loc;
  SourceLoc name_loc;
};

enum class WatchdogAction : std::uint8_t { kFault, kWarn };
/// What the watchdog makes of a host stall: a cycle over `time` whose own CPU time was within it
/// (the process was descheduled — a busy or virtual host — not the cycle's work). Either way the
/// stall is counted and raised as warning alarm 102. kFault: the watchdog judges the cycle's wall
/// time as for any overrun (a real machine: its outputs were late). kTolerate: the stalled cycle
/// is not held against the watchdog (simulated machines: nothing a stall can harm).
enum class HostStallPolicy : std::uint8_t { kFault, kTolerate };
enum class OverrunPolicy : std::uint8_t { kSkip, kAsap };

struct WatchdogSpec {
  bool enabled{false};
  Duration time{};     // > 0 when enabled
  int sensitivity{1};  // >= 1
  WatchdogAction action{WatchdogAction::kFault};
  HostStallPolicy host_stall{HostStallPolicy::kFault};
  SourceLoc loc;
};

struct TaskSpec {
  std::string name;
  Duration interval{};     // > 0
  int priority{0};         // 0 = highest, 0..31
  std::optional<int> cpu;  // >= 0
  WatchdogSpec watchdog;
  OverrunPolicy overrun{OverrunPolicy::kSkip};
  std::vector<NameRef> programs;  // in execution order
  SourceLoc loc;
  SourceLoc name_loc;
};

/// One entry of a driver's pin map (`machine.io.pins`, e.g. the modbus driver's registers): a
/// flat map of scalars, interpreted by the driver (IoDriver::set_pin_map).
struct PinMapSpec {
  std::vector<ParamSetting> fields;
  SourceLoc loc;
};

struct IoSpec {
  std::string driver{"loopback"};
  std::optional<NameRef> task;  // default: the highest-priority task (lowest number; first wins)
  std::vector<ParamSetting> params;
  std::vector<PinMapSpec> pins;  // drivers with a pin map only
  /// `driver: composite`: the drivers it combines (their pins share the io. namespace; their
  /// parameters too, or io.<name>.<param> for a child given a `name`).
  std::vector<IoSpec> drivers;
  std::string name;  // a composite's child: its optional `name` ("" = none)
  SourceLoc loc;
  SourceLoc driver_loc;
  SourceLoc name_loc;
};

/// An axis (soft limits, dynamics) as read by machining's shared section reader.
using AxisSpec = machining::LocatedAxis;

/// Which way an axis may still move in FAULT (DESIGN §11: "Z backed off"); ESTOP stops all.
enum class RetractDirection : std::int8_t { kMinus = -1, kNone = 0, kPlus = 1 };

/// `machine.safety.axes[i]`: an axis of `machine.axes` whose process-image command the
/// supervisor checks (docs/config.md, docs/safety.md).
struct SafetyAxisSpec {
  char name{'\0'};                      // 'X', 'Y' or 'Z'; '\0' until read
  NameRef velocity;                     // io.<LREAL input>, mm/s
  NameRef position;                     // io.<LREAL output>, mm
  std::optional<double> ferror_mm;      // following-error limit at v_max; absent: not checked
  std::optional<double> min_ferror_mm;  // at standstill; default ferror_mm
  RetractDirection retract{RetractDirection::kNone};
  SourceLoc loc;
};

/// `machine.safety.short_stop`: the same-cycle short stop (supervisor.hpp). A cycle whose own
/// pulses are shorted at `limit` or beyond (n_short ≥ limit · Σ pulses, Σ pulses > 0) commands
/// no supervised axis against its `retract` direction (toward the work).
struct ShortStopSpec {
  NameRef shorts;               // io.<LINT output>: the shorted pulses of this cycle
  std::vector<NameRef> pulses;  // io.<LINT output>s whose sum is all pulses of this cycle
  double limit{0.9};            // (0, 1]
  SourceLoc loc;
};

/// `machine.safety`: the runtime's safety supervisor. Absent (present == false): none.
struct SafetySpec {
  bool present{false};
  std::vector<SafetyAxisSpec> axes;
  std::optional<ShortStopSpec> short_stop;
  std::optional<NameRef> electrode_length;  // io.<LREAL output>, mm of electrode left
  double electrode_margin_mm{0.0};          // alarm 160 at or below this length
  std::optional<NameRef> wire_break;        // io.<BOOL output>, true = broken
  std::vector<NameRef> generator;           // io.<BOOL input>s held false in FAULT/ESTOP
  SourceLoc loc;
};

/// `machine.realtime`: what the runtime sets up for itself on the real clock
/// (rt_environment.hpp). Every key is optional; the defaults are what a real machine wants.
struct RealtimeSpec {
  /// The PM QoS CPU latency request held while the runtime runs, µs; nullopt = `off` (none).
  std::optional<std::int32_t> pm_qos_latency_us{0};
  std::string pm_qos_device{"/dev/cpu_dma_latency"};  // absolute path; tests point it elsewhere
  bool lock_memory{true};                             // mlockall(MCL_CURRENT | MCL_FUTURE)
  SourceLoc loc;
};

/// `machine.electrode`: the electrode the machine starts with when nothing is retained (the
/// length estimate of electrode.hpp; 0: unknown, no length compensation).
/// The tool setter (issue 33, electrode change): a reference surface the electrode touches to
/// be measured, at machine (x_mm, y_mm); z_mm is the machine Z at which an electrode of length 0
/// would touch it, so a measured length is the Z at contact − z_mm (calibrate it by touching a
/// master electrode of known length: z_mm = Z at contact − that length).
struct ToolSetterSpec {
  double x_mm{0.0}, y_mm{0.0}, z_mm{0.0};
  SourceLoc loc;
};

struct ElectrodeSpec {
  double length_mm{0.0};
  std::optional<ToolSetterSpec> tool_setter;
  SourceLoc loc;
};

struct MachineSpec {
  std::string name;
  machining::MachineKind kind{machining::MachineKind::kDrill};  // `machine.kind`
  IoSpec io;
  ElectrodeSpec electrode;
  /// `machine.condition_edit`: the condition fields an operator may change on the running
  /// machine (condition.set; machining::condition_field names them); empty: the table is
  /// read-only.
  std::vector<std::string> condition_edit;
  std::vector<AxisSpec> axes;
  SafetySpec safety;
  RealtimeSpec realtime;
  SourceLoc loc;
};

using machining::Polarity;
/// A machining condition (selected by E number) as read by machining's shared section reader.
using ConditionSpec = machining::LocatedCondition;

struct TraceSpec {
  std::vector<NameRef> variables;
  std::size_t capacity{8192};  // samples per task ring, power of two
  SourceLoc loc;
};

struct BridgeSpec {
  std::string bind{"127.0.0.1"};
  int port{7730};                 // 0 = no bridge
  std::string token_file;         // operator role
  std::string viewer_token_file;  // viewer role
  int max_sessions{8};
  std::size_t max_line_bytes{1u << 20};
  Duration read_timeout{std::chrono::seconds(60)};  // no request for this long: close
  std::size_t queue_limit{256};  // queued messages per session before events are dropped
  Duration stall_timeout{std::chrono::seconds(5)};  // dropping that long: disconnect
  std::size_t queue_bytes{std::size_t{4} << 20};    // queued bytes per session (replies + events)
  int max_pending{16};                              // connections that have not said hello yet
  Duration hello_timeout{std::chrono::seconds(5)};  // no valid hello this soon: close
  std::string tls_cert;              // PEM certificate chain; with tls_key: the bridge speaks TLS
  std::string tls_key;               // PEM private key
  bool insecure_plaintext{false};    // a network bind without TLS (loud opt-out)
  std::string audit_file;            // state-changing ops are appended here too (and always logged)
  std::vector<NameRef> status_vars;  // key pins of the status snapshot (default: docs/protocol.md)
  SourceLoc loc;
  SourceLoc tls_loc;  // where `tls:` is, for errors about its files
};

struct RetainSpec {
  std::string file;                                // empty = no retain store
  Duration min_interval{std::chrono::seconds(1)};  // rate limit of on-change writes
  std::vector<NameRef> variables;
  /// The depth a job has reached (an LREAL variable, e.g. io.depth_mm), kept in the job record
  /// the runtime retains while a part program runs (docs/runtime.md, "Restart after an unclean
  /// stop"); absent: the record has no depth.
  std::optional<NameRef> job_depth;
  /// Two more LREAL variables of the record, for resuming a drilling block where it stopped
  /// (issue 21): the Z where the drill first touched (its depth origin) and the electrode wear it
  /// had compensated since (drill-sim: cnc.job.drill.touch_z_mm, cnc.job.drill.wear_mm).
  std::optional<NameRef> job_touch_z;
  std::optional<NameRef> job_wear;
  SourceLoc loc;
  SourceLoc file_loc;  // of the `file:` value, for problems with the path itself
};

/// A fragment read through `include:`: the file as its locations name it, and the note appended
/// to every message located in it, e.g. "included from config/machines/drill-sim.yaml:74:14".
struct IncludedFile {
  std::string file;
  std::string note;
};

struct Config {
  std::string path;
  std::vector<IncludedFile> includes;  // in the order they were read
  int version{1};
  MachineSpec machine;
  std::vector<ConditionSpec> conditions;
  std::vector<TaskSpec> tasks;
  std::vector<ProgramSpec> programs;
  TraceSpec trace;
  BridgeSpec bridge;
  RetainSpec retain;
  /// Where the `mqtt:` key is (line 0: absent). The section itself is read and checked by the
  /// telemetry library (telemetry/, edm::telemetry::load_mqtt_config), which the runtime does not
  /// depend on (DESIGN §3).
  SourceLoc mqtt_loc;
  /// Where the `modbus_server:` key is (line 0: absent). Read and checked by the modbus library
  /// (modbus/, edm::modbus::parse_server_file; docs/modbus.md), like `mqtt:`.
  SourceLoc modbus_server_loc;
};

/// The conditions and soft limits in the form part programs are checked against (machining/).
machining::MachineTables to_machine_tables(const Config& cfg);

/// Puts the diagnostics in file order (the config's own file, then its fragments in the order
/// read; line, column within each) and appends "(included from F:L:C)" to those located in a
/// fragment. parse_config_*() and Runtime::build() do this; for errors found later.
std::vector<Diagnostic> with_include_notes(const Config& cfg, std::vector<Diagnostic> diags);

/// Reads and checks a config file. Throws ConfigError listing every problem (file:line:col).
Config parse_config_file(const std::string& path);
/// Same, from text (`path` names it in messages, and fragments it includes are found relative to
/// its directory).
Config parse_config_text(const std::string& text, const std::string& path);

}  // namespace edm::rt
