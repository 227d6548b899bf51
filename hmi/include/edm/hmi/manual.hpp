#pragma once
// The client side of the operator's manual functions (DESIGN §12, docs/hmi.md): reference
// (home), jog, touch-off and work offsets. The runtime runs them under its safety supervisor;
// edmhmi sends the op, then follows `manual.status` until the operation is done.
//
//   home {"axes"?: "XYZ"}                       → {"seq", "axes": "ZXY"}
//   jog {"axis", "distance"} | {"axis", "velocity"} → {"seq", "deadman_ms"}; jog.stop → {"seq"}
//   touch {"target": "z|x+|x-|y+|y-|center"}    → {"seq"}
//   manual.status → {"mode", "busy", "seen_seq", "referenced", "result": {"seq", "op", "target",
//                    "ok", "error", "x", "y", "z", "size"}}
// Every request gets a sequence number; the result names the request it answers.
//   offset.get, offset.set {"frame", "x"?, "y"?, "z"?}
//
// Non-RT. The parsing and checking functions are pure (thread-compatible); wait_manual() calls
// the client (one thread at a time per Client, like every request).

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "edm/bridge/client.hpp"
#include "edm/hmi/work_offsets.hpp"

namespace edm::hmi {

/// The last finished manual operation, as the runtime reports it.
struct ManualResult {
  std::uint64_t seq{0};  // the request it answers
  std::string op;        // home, jog, touch
  std::string target;    // touch: z, x+, x-, y+, y-, center
  bool ok{false};
  std::string error;
  std::optional<double> x_mm, y_mm, z_mm;  // machine coordinates (touch: surface, edge, centre)
  std::optional<double> size_mm;           // touch center: the bore's diameter
};

struct ManualStatus {
  std::string mode;  // idle, home, jog, touch
  bool busy{false};
  std::optional<std::uint64_t> seen_seq;            // the newest request the runtime has taken
  std::array<std::optional<bool>, 3> referenced{};  // X, Y, Z (absent: not reported)
  std::optional<ManualResult> result;
};

/// A manual.status reply. False with `error` set when a field has the wrong type.
bool manual_status_from_json(const bridge::Json& j, ManualStatus& out, std::string& error);

/// "XY", "zx" → "XY", "XZ" in the order given, upper case; empty `error` when fine. Refused: an
/// empty text, a letter other than X Y Z, an axis twice.
std::string normalise_axes(std::string_view text, std::string& error);

/// One axis letter X, Y or Z (either case) → upper case; nullopt otherwise.
std::optional<char> parse_axis(std::string_view text);

/// Incremental jog: |distance| within 0.001..10 mm (the sign is the direction).
inline constexpr double kJogMinMm = 0.001;
inline constexpr double kJogMaxMm = 10.0;
[[nodiscard]] bool valid_jog_distance(double mm) noexcept;

/// The touch-off targets, as the protocol spells them.
enum class TouchTarget : std::uint8_t { kZ, kXPlus, kXMinus, kYPlus, kYMinus, kCenter };
std::optional<TouchTarget> parse_touch_target(std::string_view text);  // case-insensitive
std::string_view to_string(TouchTarget t) noexcept;

/// The offset.set parameters that put a touch result into `frame` ("G54"): z → z, x± → x,
/// y± → y, center → x and y. nullopt when the result lacks a needed coordinate.
std::optional<bridge::Json> offset_set_for_touch(std::string_view frame, TouchTarget t,
                                                 const ManualResult& r);

/// The runtime's error text of a manual operation ended by jog.stop (ManualError::kStopped): the
/// expected end of a continuous jog.
inline constexpr std::string_view kStoppedByOperator = "stopped by the operator";

/// "touch x+ ok X 12.3456 (machine)" / "home ok" / "jog failed: <the runtime's error>"; the
/// coordinates only for a touch (they are what it found).
std::string format_manual_result(const ManualResult& r);

/// What wait_manual saw.
struct ManualWait {
  bool done{false};         // the operation finished (result holds it)
  bool interrupted{false};  // `interrupt` was set first
  std::string error;        // manual.status refused or malformed, or the operation never ended
  ManualStatus status;      // the last one read
};

/// Polls manual.status every `period` until the runtime has taken request `seq`, is not busy
/// and its last result answers a request at or after `result_from` (for one request: its own
/// seq; after a continuous jog's jog.stop, the first jog's), or `interrupt` is set, or `timeout`
/// passes.
ManualWait wait_manual(bridge::Client& client, std::uint64_t seq, std::uint64_t result_from,
                       const std::atomic<bool>& interrupt,
                       std::chrono::milliseconds period = std::chrono::milliseconds(50),
                       std::chrono::milliseconds timeout = std::chrono::minutes(30));

/// manual.status's view of request `seq` (see wait_manual): done when taken, not busy and
/// answered by a result at or after `result_from`.
[[nodiscard]] bool manual_done(const ManualStatus& s, std::uint64_t seq,
                               std::uint64_t result_from) noexcept;

/// The jog refresh period for the runtime's dead-man timeout: deadman/3, at least 10 ms.
std::chrono::milliseconds jog_refresh_period(double deadman_ms) noexcept;

}  // namespace edm::hmi
