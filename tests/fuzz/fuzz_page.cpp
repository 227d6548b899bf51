// fuzz_page: any bytes as the text messages a browser sends `edmhmi serve` over its WebSocket
// (hmi/, docs/web.md "The WebSocket"). The input is cut into messages at 0xFF bytes (never part
// of a UTF-8 text message); they go, in order, through the session's handler as a socket would
// pass them: page_action() (strict JSON, schema, role) and, for a command, run_page_command()
// against an in-memory backend (tests/web/fake_page_backend.hpp) — the path that aborted edmhmi
// on a wrong type and a deep array (issue 31). The first message that logs in decides the role
// (token "viewer": viewer, else operator). Invariants: nothing throws; every reply encodes to one
// JSON object that parses back strictly; a command reply carries its id and a boolean "ok"; a
// viewer never reaches an acting command; a relayed command reaches the backend as its own op.

#include <string>
#include <string_view>

#include "edm/hmi/web_command.hpp"
#include "edm/hmi/web_job.hpp"
#include "fuzz/fuzz_entry.hpp"
#include "web/fake_page_backend.hpp"

namespace edm::fuzz {
namespace {

using bridge::Json;
using hmi::PageAction;

Json check_text(const Json& reply) {
  const std::string text = hmi::page_text(reply);
  Json back;
  std::string why;
  EDM_FUZZ_CHECK(bridge::parse_json_strict(text, back, why));
  EDM_FUZZ_CHECK(back.is_object());
  EDM_FUZZ_CHECK(back.contains("t") && back["t"].is_string());
  return back;
}

void one_message(std::string_view text, std::optional<bridge::Role>& role,
                 hmi::test::FakePageBackend& backend) {
  const PageAction a = hmi::page_action(text, role);
  switch (a.kind) {
    case PageAction::Kind::kClose:
      EDM_FUZZ_CHECK(!role);
      check_text(a.reply);
      return;
    case PageAction::Kind::kLogin:
      EDM_FUZZ_CHECK(!role);
      EDM_FUZZ_CHECK(a.token.size() <= hmi::kMaxPageTokenBytes);
      role = a.token == "viewer" ? bridge::Role::kViewer : bridge::Role::kOperator;
      return;
    case PageAction::Kind::kHeld: EDM_FUZZ_CHECK(role.has_value()); return;
    case PageAction::Kind::kReply: {
      EDM_FUZZ_CHECK(role.has_value());
      const Json back = check_text(a.reply);
      if (back["t"] == "reply") {
        EDM_FUZZ_CHECK(back.contains("ok") && back["ok"] == false);
        EDM_FUZZ_CHECK(back.contains("code") && back["code"].is_string());
      }
      return;
    }
    case PageAction::Kind::kRun: break;
  }
  EDM_FUZZ_CHECK(role.has_value());
  const hmi::PageCommand& c = a.command;
  const hmi::PageOpInfo& info = hmi::page_op_info(c.op);
  EDM_FUZZ_CHECK(*role == bridge::Role::kOperator || info.viewer);
  EDM_FUZZ_CHECK(c.text.size() <= hmi::kMaxWebProgramBytes);
  EDM_FUZZ_CHECK(c.id.is_null() || c.id.is_number_integer() || c.id.is_string());
  const std::size_t calls = backend.calls.size();
  const Json reply = hmi::run_page_command(backend, c, 1);
  const Json back = check_text(reply);
  EDM_FUZZ_CHECK(back["t"] == "reply");
  EDM_FUZZ_CHECK(back.contains("ok") && back["ok"].is_boolean());
  EDM_FUZZ_CHECK(back.contains("id") && back["id"] == c.id);
  EDM_FUZZ_CHECK(back.contains("op") && back["op"] == info.name);
  EDM_FUZZ_CHECK(backend.calls.size() > calls);
  const std::string& last = backend.calls.back();
  if (last.starts_with("relay:")) {
    EDM_FUZZ_CHECK(last.substr(6) == info.name);
    // What reached edmplc's side is an object (unless the fake failed before it looked).
    EDM_FUZZ_CHECK(back["ok"] == false || backend.last_params.is_object());
  }
  if (backend.calls.size() > 4096) backend.calls.clear();
}

}  // namespace

int page_one_input(const std::uint8_t* data, std::size_t size) {
  hmi::test::FakePageBackend backend;
  // A backend failure now and then: it must come back as an "internal" reply, nothing more.
  backend.throw_next = size > 0 && data[0] == 'T';
  std::optional<bridge::Role> role;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  for (;;) {
    const std::size_t cut = rest.find('\xff');
    one_message(rest.substr(0, cut), role, backend);
    if (cut == std::string_view::npos) break;
    rest.remove_prefix(cut + 1);
  }
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::page_one_input)
