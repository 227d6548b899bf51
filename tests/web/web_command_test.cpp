// A browser's message to its reply without a socket (hmi/include/edm/hmi/web_command.hpp, issue 31
// item 2): roles, the log-in first, and no exception out of a handler, whatever the backend
// throws — the reply says "internal" and the session goes on.
#include "edm/hmi/web_command.hpp"

#include <gtest/gtest.h>

#include "web/fake_page_backend.hpp"

namespace edm::hmi::test {
namespace {

using bridge::Json;
using bridge::Role;
using Kind = PageAction::Kind;

Json run_text(FakePageBackend& b, const std::string& text, Role role = Role::kOperator) {
  const PageAction a = page_action(text, role);
  EXPECT_EQ(a.kind, Kind::kRun) << text << " " << a.reply.dump();
  return a.kind == Kind::kRun ? run_page_command(b, a.command, 7) : a.reply;
}

TEST(WebCommand, before_the_log_in_only_a_log_in_is_taken) {
  EXPECT_EQ(page_action(R"({"t":"login","token":"x"})", std::nullopt).kind, Kind::kLogin);
  EXPECT_EQ(page_action(R"({"t":"login","token":"x"})", std::nullopt).token, "x");
  for (const char* text : {R"({"t":"cmd","op":"estop"})", R"({"t":"held"})", "[[[", "{}"}) {
    EXPECT_EQ(page_action(text, std::nullopt).kind, Kind::kClose) << text;
  }
  EXPECT_EQ(page_action(R"({"t":"login","token":"x"})", Role::kViewer).kind, Kind::kReply);
}

TEST(WebCommand, a_viewer_is_refused_every_command_that_could_act) {
  for (const char* text :
       {R"({"t":"cmd","id":1,"op":"estop"})", R"({"t":"cmd","id":1,"op":"home","axes":"Z"})",
        R"({"t":"cmd","id":1,"op":"jog","axis":"X","distance":1})",
        R"({"t":"cmd","id":1,"op":"jog.hold","axis":"X","velocity":1})",
        R"({"t":"cmd","id":1,"op":"jog.stop"})", R"({"t":"cmd","id":1,"op":"touch","target":"z"})",
        R"({"t":"cmd","id":1,"op":"offset.set","frame":"G54","z":1})",
        R"({"t":"cmd","id":1,"op":"mdi","line":"G00 Z5"})",
        R"({"t":"cmd","id":1,"op":"start_from","line":5})",
        R"({"t":"cmd","id":1,"op":"start","dry_run":true})",
        R"({"t":"cmd","id":1,"op":"ack","seq":1})"}) {
    const PageAction a = page_action(text, Role::kViewer);
    ASSERT_EQ(a.kind, Kind::kReply) << text;
    EXPECT_EQ(a.reply["code"], "forbidden") << text;
    EXPECT_EQ(a.reply["id"], 1) << text;
  }
  FakePageBackend b;
  EXPECT_EQ(
      run_text(b, R"({"t":"cmd","id":2,"op":"var.list","prefix":"io."})", Role::kViewer)["ok"],
      true);
  EXPECT_EQ(b.calls, std::vector<std::string>{"relay:var.list"});
}

TEST(WebCommand, replies_echo_id_and_op_and_relay_only_checked_fields) {
  FakePageBackend b;
  const Json r = run_text(b, R"({"t":"cmd","id":"q","op":"jog","axis":"X","distance":1})");
  EXPECT_EQ(r["t"], "reply");
  EXPECT_EQ(r["id"], "q");
  EXPECT_EQ(r["op"], "jog");
  EXPECT_EQ(r["ok"], true);
  EXPECT_EQ(b.last_params, (Json{{"axis", "X"}, {"distance", 1}}));
  const Json stop = run_text(b, R"({"t":"cmd","id":3,"op":"jog.stop"})");
  EXPECT_EQ(stop["ok"], true);
  EXPECT_EQ(b.calls.back(), "relay:jog.stop");
  // A bad command's reply carries its id, so the page's promise resolves.
  const PageAction bad =
      page_action(R"({"t":"cmd","id":9,"op":"start","dry_run":"yes"})", Role::kOperator);
  ASSERT_EQ(bad.kind, Kind::kReply);
  EXPECT_EQ(bad.reply["t"], "reply");
  EXPECT_EQ(bad.reply["id"], 9);
  EXPECT_EQ(bad.reply["ok"], false);
  EXPECT_EQ(bad.reply["code"], "bad_request");
}

TEST(WebCommand, nothing_the_backend_throws_escapes) {
  FakePageBackend b;
  b.throw_next = true;
  const Json r = run_text(b, R"({"t":"cmd","id":4,"op":"check","text":"G0 X1"})");
  EXPECT_EQ(r["ok"], false);
  EXPECT_EQ(r["code"], "internal");
  EXPECT_EQ(r["id"], 4);
  b.throw_non_std = true;
  const Json r2 = run_text(b, R"({"t":"cmd","id":5,"op":"ack","seq":3})");
  EXPECT_EQ(r2["code"], "internal");
  // The next command works again.
  EXPECT_EQ(run_text(b, R"({"t":"cmd","id":6,"op":"estop"})")["ok"], true);
}

TEST(WebCommand, a_reply_with_broken_utf8_is_still_sent) {
  FakePageBackend b;
  const Json r = run_text(b, R"({"t":"cmd","id":1,"op":"job"})", Role::kViewer);
  const std::string text = page_text(r);
  EXPECT_NE(text.find("\"t\":\"reply\""), std::string::npos);
  Json back;
  std::string why;
  EXPECT_TRUE(bridge::parse_json_strict(text, back, why)) << why;
}

}  // namespace
}  // namespace edm::hmi::test
