#pragma once
// What a browser's decoded message does (docs/web.md "The WebSocket"), apart from the socket:
//
//   text ─▶ page_action() ─▶ reply at once | log in | "held" | run a PageCommand (inline or on
//                                                                          a worker lane)
//   PageCommand ─▶ run_page_command(backend) ─▶ the reply {"t":"reply","id","op","ok",…}
//
// The backend is the hub (edmplc through the one bridge session, the job, the manual functions);
// the fuzz target (tests/fuzz/fuzz_page.cpp) and the tests give a fake one. Nothing here lets an
// exception out: a handler that throws, whatever it throws, is the reply
// {"ok": false, "code": "internal", …} to that command only.
//
// Thread-safety: page_action() is pure; run_page_command() is as thread-safe as the backend
// (WebHub's members may be called from its worker threads).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "edm/bridge/protocol.hpp"
#include "edm/hmi/job_queue.hpp"
#include "edm/hmi/web_message.hpp"

namespace edm::hmi {

/// What run_page_command() needs. Each call returns the page's reply body ({"ok", "body"?,
/// "code"?, "message"?, …}) and may block on bridge requests, except those marked "never blocks".
class PageBackend {
 public:
  virtual ~PageBackend() = default;
  /// An op relayed to edmplc with `params` (already type-checked).
  virtual bridge::Json relay(std::string_view op, const bridge::Json& params) = 0;
  virtual bridge::Json check(const std::string& text, const std::string& name) = 0;
  virtual bridge::Json upload(const std::string& text, const std::string& name) = 0;
  virtual bridge::Json start_job(bool dry_run) = 0;
  virtual bridge::Json start_from(std::int32_t line, std::optional<double> depth_done_mm,
                                  bool dry_run) = 0;
  virtual bridge::Json mdi(const std::string& line) = 0;
  virtual bridge::Json jog_hold(std::uint64_t owner, const std::string& axis,
                                double velocity_mm_s) = 0;
  /// jog.stop from any operator ends the hold the server refreshes. Never blocks.
  virtual void jog_stop_hold() = 0;
  /// The browser `owner` let go of its held jog. Never blocks.
  virtual void jog_release(std::uint64_t owner) = 0;
  virtual bridge::Json touch(const std::string& target, const std::string& set_frame) = 0;
  virtual bridge::Json offset_set(const bridge::Json& params) = 0;
  /// Marks the alarms up to `seq` acknowledged. Never blocks.
  virtual void acknowledge(std::uint64_t seq) = 0;
  /// What the hub follows anyway (null: none yet). Never block.
  virtual bridge::Json manual_status() = 0;
  virtual bridge::Json offsets() = 0;
  virtual bridge::Json job_snapshot() = 0;
  /// tasks.stats and the web server's own counters.
  virtual bridge::Json stats() = 0;
  /// The queue (web_shift.hpp): a program checked, then added; "clear", "start", "stop"; the
  /// electrode measurement. Never block (the procedures run on threads of their own), except
  /// queue_add's check.
  virtual bridge::Json queue_add(const QueueItem& item) = 0;
  virtual bridge::Json queue_control(std::string_view action) = 0;
  virtual bridge::Json queue_snapshot() = 0;
  virtual bridge::Json electrode_measure(const std::string& reference,
                                         const std::string& frame) = 0;
  /// condition.set relayed; once done, the machine's tables are fetched again (every later
  /// check and upload uses the edit).
  virtual bridge::Json condition_set(const bridge::Json& params) = 0;
};

/// Runs one command and returns its reply: {"t":"reply","id","op","ok",…}. Never throws.
[[nodiscard]] bridge::Json run_page_command(PageBackend& backend, const PageCommand& command,
                                            std::uint64_t owner) noexcept;

/// What a session does with one text message.
struct PageAction {
  enum class Kind : std::uint8_t {
    kReply,  // send `reply` (an error, or a refusal); the session goes on
    kClose,  // close the socket, saying `reply`'s message (no log-in first)
    kLogin,  // check `token`
    kHeld,   // the jog button is still down
    kRun,    // run `command` (on page_op_info(command.op).lane)
  };
  Kind kind{Kind::kReply};
  bridge::Json reply;
  std::string token;
  PageCommand command;
};

/// Decodes `text` and decides, for a browser logged in as `role` (none yet: only a log-in is
/// taken). A viewer's command that could act is refused here ("forbidden"). Never throws.
[[nodiscard]] PageAction page_action(std::string_view text,
                                     std::optional<bridge::Role> role) noexcept;

/// The reply to a command that was not run: {"t":"reply","id","op"?,"ok":false,"code","message"}.
[[nodiscard]] bridge::Json page_refusal(const bridge::Json& id, std::string_view code,
                                        std::string_view message, std::string_view op = {});

/// Compact text of a reply or event for the socket; invalid UTF-8 replaced. Never throws except
/// std::bad_alloc.
[[nodiscard]] std::string page_text(const bridge::Json& j);

}  // namespace edm::hmi
