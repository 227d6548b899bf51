#pragma once
// The page's WebSocket messages (docs/web.md "The WebSocket"), decoded strictly before anything
// acts on them:
//   1. the bridge's parser (bridge::parse_json_strict): nesting deeper than bridge::kMaxJsonDepth
//      is refused by a flat scan before any parser runs (a 400,000-deep array never reaches a
//      recursive one), and so is a repeated key ({"op":"job","op":"estop"});
//   2. a typed schema per message type ("login", "held", "cmd") and per command: every field is
//      known, of its type and within its size; a field that is not, or a required one missing,
//      is an error that names the field — never an exception.
// What decodes is a PageCommand whose fields have the types the handlers use, so no handler
// reads a JSON value of an unchecked type (nlohmann's type_error aborted edmhmi, issue 31).
//
// Pure functions; thread-safe; noexcept (an allocation failure is reported as an error).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "edm/bridge/codec.hpp"

namespace edm::hmi {

/// Size bounds of a message's fields (bytes). The message itself is bounded by the socket
/// (kMaxWebMessageBytes, web_session.hpp).
inline constexpr std::size_t kMaxPageTokenBytes = 1024;  // edmplc's longest token
inline constexpr std::size_t kMaxPageIdBytes = 64;       // a string id
inline constexpr std::size_t kMaxPageNameBytes = 256;    // a part name, a variable name, a prefix
inline constexpr std::size_t kMaxPageWordBytes = 16;     // an axis, a frame, a touch target
inline constexpr std::size_t kMaxPageMdiBytes = 1024;    // one MDI line
inline constexpr std::size_t kMaxPageVarNames = 256;     // names of one var.read

/// Every command a browser may send.
enum class PageOp : std::uint8_t {
  kCheck,
  kUpload,
  kStart,
  kStartFrom,
  kMdi,
  kCycleHold,
  kCycleResume,
  kCycleStop,
  kEstop,
  kReset,
  kFeedOverride,
  kHome,
  kJog,
  kJogHold,
  kJogRelease,
  kJogStop,
  kTouch,
  kOffsetGet,
  kOffsetSet,
  kManualStatus,
  kAck,
  kJob,
  kStats,
  kVarList,
  kVarRead,
  kVarWrite,
  kVarForce,
  kVarUnforce,
  kElectrodeGet,
  kElectrodeChange,
  kElectrodeMeasure,
  kJobsGet,
  kQueue,
  kQueueAdd,
  kQueueClear,
  kQueueStart,
  kQueueStop,
  kConditionSet,
};

/// Where a command runs: at once on the I/O thread (it never blocks), or on one of the hub's
/// worker lanes (it makes blocking bridge requests).
enum class PageLane : std::uint8_t { kInline, kMachine, kProgram };

struct PageOpInfo {
  std::string_view name;
  PageOp op;
  bool viewer;  // a viewer may send it (it changes neither the machine nor the job)
  PageLane lane;
};
/// nullptr for a name that is no command.
[[nodiscard]] const PageOpInfo* find_page_op(std::string_view name) noexcept;
[[nodiscard]] const PageOpInfo& page_op_info(PageOp op) noexcept;

/// A decoded command. Only the fields of its op are set; `params` holds what is relayed to
/// edmplc as it is (home, jog, offset.set, feed.override, var.*, electrode.change, jobs.get),
/// already type-checked — edmplc
/// checks values, ranges and the machine's state.
struct PageCommand {
  bridge::Json id;  // null, an integer or a string of ≤ kMaxPageIdBytes: echoed in the reply
  PageOp op{PageOp::kJob};
  std::string text;                       // check, upload, queue.add: the G-code
  std::string name{"program.nc"};         // check, upload, queue.add: the part's name
  std::int32_t repeat{1};                 // queue.add
  double step_x_mm{0.0}, step_y_mm{0.0};  // queue.add
  bool dry_run{false};                    // start, start_from
  std::int32_t from_line{0};              // start_from: the G-code line
  std::optional<double> depth_done_mm;    // start_from
  std::string mdi_line;                   // mdi
  std::string axis;                       // jog.hold
  double velocity_mm_s{0.0};              // jog.hold
  std::string target, set_frame;          // touch; electrode.measure: reference, frame
  std::uint64_t seq{0};                   // ack: alarms up to this one
  bridge::Json params = bridge::Json::object();
};

struct PageLogin {
  std::string token;
};
struct PageHeld {};  // a jog button is still down (no reply)

/// A message that does not decode. `code` is "bad_json" (not a JSON object, too deep, a repeated
/// key) or "bad_request" (a wrong type, an unknown or missing field, an unknown command); `id` is
/// the command's id when it was readable (the error is then that command's reply).
struct PageError {
  std::string code;
  std::string message;
  bridge::Json id;
  bool is_command{false};
};

using PageMessage = std::variant<PageError, PageLogin, PageHeld, PageCommand>;

/// Decodes one text message of a browser.
[[nodiscard]] PageMessage decode_page_message(std::string_view text) noexcept;

/// `s` cut to `max` bytes with every byte outside printable ASCII as '?': what an error message
/// may quote of a browser's input.
[[nodiscard]] std::string quote_untrusted(std::string_view s, std::size_t max = 32);

}  // namespace edm::hmi
