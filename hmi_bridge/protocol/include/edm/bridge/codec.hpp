#pragma once
// JSON encoding of the protocol's messages (docs/protocol.md): requests, replies, errors,
// events, motion blocks, status, and the program checksum.
//
// Thread-safety: pure functions (thread-safe); Crc32 is a value type (thread-compatible).
// Not RT-safe: everything here may allocate.

#include <boost/crc.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "edm/bridge/protocol.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::bridge {

using Json = nlohmann::json;

// ---- motion blocks ------------------------------------------------------------------------
// {"kind": "drill", "line": 12, "col": 1, "target": [x, y, z], "centre": [x, y, z], "turns": 0,
//  "feed_mm_s": 0.5, "condition": 1, "z_travel_mm": 10.6, "final_radius_mm": 0, "dwell_s": 0,
//  "on": false, "electrode_ref_mm": 300}. Only `kind` is required; absent fields take the
//  MotionBlock defaults, and the
// encoder leaves out fields equal to their default (a 100,000-block upload stays small).

Json to_json(const machining::MotionBlock& b);
/// Decodes one block; on failure returns false and says which field is wrong in `error`.
/// Unknown fields, wrong types, non-finite numbers and out-of-range integers are errors.
bool from_json(const Json& j, machining::MotionBlock& out, std::string& error);

// ---- program checksum ---------------------------------------------------------------------
// CRC-32 (IEEE 802.3, the zlib/PNG polynomial; Python: zlib.crc32) over each block's canonical
// 130-byte little-endian record, in program order:
//   u8 kind, i32 line, i32 col, f64 target.x/y/z, f64 centre.x/y/z, i32 turns, f64 feed_mm_s,
//   i32 condition, f64 z_travel_mm, f64 depth_mm, f64 depth_done_mm, f64 resume_touch_z_mm,
//   f64 resume_wear_mm, f64 final_radius_mm, f64 dwell_s, u8 on
// (Python: struct.pack('<Bii6didi7dB', ...)), followed by f64 electrode_ref_mm when it is not 0
// ('<Bii6didi7dBd', 138 bytes). It covers the decoded values, so it catches a lost, repeated or
// reordered chunk and any number the JSON round trip changed.
inline constexpr std::size_t kBlockRecordBytes = 130;

// Incremental: update() in any number of pieces gives the CRC of their concatenation.
class Crc32 {
 public:
  void update(std::span<const std::uint8_t> bytes) noexcept;
  void update(const machining::MotionBlock& b) noexcept;
  [[nodiscard]] std::uint32_t value() const noexcept { return crc_.checksum(); }

 private:
  boost::crc_32_type crc_;  // CRC-32/ISO-HDLC: reflected 0x04C11DB7, init and xorout 0xFFFFFFFF
};

std::uint32_t program_checksum(std::span<const machining::MotionBlock> blocks) noexcept;
/// 8 lower-case hex digits.
std::string format_checksum(std::uint32_t crc);
/// Accepts the 8-hex-digit string form; false otherwise.
bool parse_checksum(const Json& j, std::uint32_t& out) noexcept;

// ---- requests, replies, events --------------------------------------------------------------

/// {"id": id, "op": op, ...params}. params must be an object or null.
Json make_request(std::int64_t id, std::string_view op, const Json& params = Json::object());
/// hello's parameters: {"protocol": kProtocolVersion, "token": token[, "peer": peer]}. `peer`
/// (a relaying HMI's end client, e.g. "192.0.2.7:51234") is left out when empty; the server
/// refuses one that is not valid_hello_peer() with bad_request.
Json hello_params(std::string_view token, std::string_view peer = {});
/// {"id": id, "ok": true, ...body}. body must be an object or null; id null is left out.
Json make_reply(const Json& id, const Json& body = Json::object());
/// {"id": id, "ok": false, "error": {"code", "message"[, "details"]}}.
Json make_error(const Json& id, ErrorCode code, std::string_view message,
                const Json& details = nullptr);
/// {"event": name, "seq": seq, ...body}.
Json make_event(std::string_view name, std::uint64_t seq, const Json& body = Json::object());

/// Parses one JSON text strictly: nesting deeper than kMaxJsonDepth and duplicate object keys
/// are errors (a repeated "op" must not pick the last one). On failure returns false and says
/// why in `error`, without quoting the input. Never recursive over the input's depth.
bool parse_json_strict(std::string_view text, Json& out, std::string& error);

/// One line as the server sees it: a JSON object with a string `op` (id optional).
struct ParsedRequest {
  Json id;  // null when absent
  std::string op;
  Json msg;  // the whole object
};
/// Parses one line (without its newline). On failure returns nullopt and sets code/message:
/// kBadJson for text that is not a JSON object, kBadRequest for a missing or non-string op or an
/// id that is neither a number nor a string.
std::optional<ParsedRequest> parse_request(std::string_view line, ErrorCode& code,
                                           std::string& message, Json& id_if_known);

/// Compact single-line text plus '\n'. Invalid UTF-8 in strings is replaced, never thrown.
std::string to_line(const Json& j);

// ---- status -------------------------------------------------------------------------------

/// The `status` reply body and the `status` event body.
/// The job a run from a block may resume: the one an unclean stop interrupted (until the next job
/// begins) or the last one, when it was aborted (stop, fault, E-stop).
struct LastJob {
  std::string outcome;  // interrupted, aborted
  std::uint64_t block{0};
  std::int32_t line{0};
  std::optional<double> depth_mm;    // retain.job_depth's variable then (the controller's estimate)
  std::optional<double> touch_z_mm;  // retain.job_touch_z's: the drill's depth origin (machine Z)
  std::optional<double> wear_mm;     // retain.job_wear's: the wear compensated since the touch
};

struct StatusMessage {
  std::string state;        // OFF, READY, RUNNING, HOLD, FAULT, ESTOP
  int cause{0};             // alarm code of the last entry into a safe state (0 = none)
  double t_s{0.0};          // release time of the cycle the snapshot was taken in (s)
  std::uint64_t cycle{0};   // that cycle's number (of the I/O task)
  std::string job_outcome;  // none, running, finished, aborted
  std::uint64_t job_generation{0};
  std::uint64_t job_block{0};  // index of the block being executed
  std::uint64_t job_blocks{0};
  std::int32_t job_line{0};                          // its G-code line
  std::uint64_t job_jobs_started{0};                 // jobs begun since start (any slot)
  std::string job_slot{"main"};                      // the current or last job's: main, mdi
  std::optional<LastJob> job_last;                   // job.last: a job that may be resumed
  std::vector<std::pair<std::string, double>> vars;  // the configured key variables
  std::uint64_t dropped{0};  // events this session has lost to a full queue (events only)
};
Json to_json(const StatusMessage& s);
bool from_json(const Json& j, StatusMessage& out, std::string& error);

}  // namespace edm::bridge
