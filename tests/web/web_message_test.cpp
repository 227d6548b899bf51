// The page's messages decoded strictly (hmi/include/edm/hmi/web_message.hpp, issue 31 item 2):
// the bridge's parser bounds (nesting, repeated keys) before any recursive parser, a typed
// schema per message and command, and errors that name the field instead of exceptions.
#include "edm/hmi/web_message.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

namespace edm::hmi::test {
namespace {

using bridge::Json;

PageError error_of(const std::string& text) {
  const PageMessage m = decode_page_message(text);
  EXPECT_TRUE(std::holds_alternative<PageError>(m)) << text;
  return std::holds_alternative<PageError>(m) ? std::get<PageError>(m) : PageError{};
}

PageCommand command_of(const std::string& text) {
  const PageMessage m = decode_page_message(text);
  EXPECT_TRUE(std::holds_alternative<PageCommand>(m))
      << text << " → "
      << (std::holds_alternative<PageError>(m) ? std::get<PageError>(m).message : "");
  return std::holds_alternative<PageCommand>(m) ? std::get<PageCommand>(m) : PageCommand{};
}

/// `depth` nested arrays around 1.
std::string nested(std::size_t depth) {
  return std::string(depth, '[') + "1" + std::string(depth, ']');
}

// The probe of issue 31: these aborted edmhmi (nlohmann type_error, rc -6).
TEST(WebMessage, wrong_json_types_are_errors_naming_the_field) {
  const PageError name = error_of(R"({"t":"cmd","id":3,"op":"check","text":"G0 X1","name":1})");
  EXPECT_EQ(name.code, "bad_request");
  EXPECT_TRUE(name.is_command);
  EXPECT_EQ(name.id, 3);
  EXPECT_NE(name.message.find("'name'"), std::string::npos) << name.message;
  const PageError dry = error_of(R"({"t":"cmd","id":"a","op":"start","dry_run":"yes"})");
  EXPECT_EQ(dry.code, "bad_request");
  EXPECT_EQ(dry.id, "a");
  EXPECT_NE(dry.message.find("'dry_run' must be true or false"), std::string::npos) << dry.message;
  for (const char* text : {R"({"t":"cmd","op":"start_from","line":"5"})",
                           R"({"t":"cmd","op":"start_from","line":5.5})",
                           R"({"t":"cmd","op":"start_from","line":4294967296})",
                           R"({"t":"cmd","op":"jog.hold","axis":"X","velocity":"1"})",
                           R"({"t":"cmd","op":"jog.hold","axis":1,"velocity":1})",
                           R"({"t":"cmd","op":"touch","target":{"a":1}})",
                           R"({"t":"cmd","op":"ack","seq":-1})",
                           R"({"t":"cmd","op":"ack","seq":"1"})",
                           R"({"t":"cmd","op":"mdi","line":"G0 X1\nG0 X2"})",
                           R"({"t":"cmd","op":"var.read","names":["a",2]})",
                           R"({"t":"cmd","op":"var.read","names":[]})",
                           R"({"t":"cmd","op":"var.write","name":"x","value":[1]})",
                           R"({"t":"cmd","op":"var.write","name":"x","value":null})",
                           R"({"t":"cmd","op":"feed.override","percent":true})",
                           R"({"t":"cmd","op":"offset.set","frame":"G54","z":"1"})",
                           R"({"t":"cmd","op":"upload","text":7})",
                           R"({"t":"cmd","op":"queue.add","text":"M30","repeat":2.5})",
                           R"({"t":"cmd","op":"queue.add","text":"M30","step_x":"10"})",
                           R"({"t":"cmd","op":"queue.add","repeat":2})",
                           R"({"t":"cmd","op":"electrode.change","kind":"tube"})",
                           R"({"t":"cmd","op":"electrode.change","electrode":"E2","size_mm":"1"})",
                           R"({"t":"cmd","op":"electrode.measure","reference":"setter","frame":5})",
                           R"({"t":"cmd","op":"electrode.measure"})",
                           R"({"t":"cmd","op":"jobs.get","limit":-1})"}) {
    const PageError e = error_of(text);
    EXPECT_EQ(e.code, "bad_request") << text;
    EXPECT_FALSE(e.message.empty()) << text;
  }
}

TEST(WebMessage, deep_nesting_is_refused_before_any_parser_sees_it) {
  // 400,000 levels in `job` and in var.read's names (SIGSEGV in the issue), and in the envelope.
  for (const std::string& text : {R"({"t":"cmd","op":"job","x":)" + nested(400000) + "}",
                                  R"({"t":"cmd","op":"var.read","names":)" + nested(400000) + "}",
                                  nested(400000), std::string(400000, '{')}) {
    const auto t0 = std::chrono::steady_clock::now();
    const PageError e = error_of(text);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0)
            .count();
    EXPECT_EQ(e.code, "bad_json");
    EXPECT_NE(e.message.find("nested deeper than"), std::string::npos) << e.message;
    EXPECT_LT(ms, 500) << "a flat scan, not a parse";
  }
  // The bound is the bridge's: 32 levels pass the scan (then the schema refuses the field).
  const PageError at_bound =
      error_of(R"({"t":"cmd","op":"var.read","names":)" + nested(bridge::kMaxJsonDepth - 1) + "}");
  EXPECT_EQ(at_bound.code, "bad_request");
}

TEST(WebMessage, repeated_keys_and_non_objects_are_bad_json) {
  EXPECT_EQ(error_of(R"({"t":"cmd","op":"job","op":"estop"})").code, "bad_json");
  EXPECT_EQ(error_of(R"({"t":"cmd","t":"login","op":"job"})").code, "bad_json");
  EXPECT_EQ(error_of(R"([1,2])").code, "bad_json");
  EXPECT_EQ(error_of("not json").code, "bad_json");
  EXPECT_EQ(error_of("").code, "bad_json");
  EXPECT_EQ(error_of("{\"t\":\"cmd\",\"op\":\"job\"} trailing").code, "bad_json");
}

TEST(WebMessage, envelope_schema) {
  EXPECT_EQ(error_of(R"({"op":"job"})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":7})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":"shutdown"})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":"held","x":1})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":"login"})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":"login","token":5})").code, "bad_request");
  EXPECT_EQ(error_of(R"({"t":"login","token":"a","x":1})").code, "bad_request");
  EXPECT_EQ(
      error_of(R"({"t":"login","token":")" + std::string(kMaxPageTokenBytes + 1, 'a') + R"("})")
          .code,
      "bad_request");
  EXPECT_TRUE(std::holds_alternative<PageHeld>(decode_page_message(R"({"t":"held"})")));
  const PageMessage login = decode_page_message(R"({"t":"login","token":""})");
  ASSERT_TRUE(std::holds_alternative<PageLogin>(login));
  EXPECT_EQ(std::get<PageLogin>(login).token, "");
  // ids: integers and short strings are echoed; anything else is refused with no id.
  EXPECT_EQ(command_of(R"({"t":"cmd","id":-4,"op":"job"})").id, -4);
  for (const char* id : {"1.5", "[1]", "{}", "true",
                         R"(")"
                         "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx"
                         R"(")"}) {
    const PageError e = error_of(std::string(R"({"t":"cmd","op":"job","id":)") + id + "}");
    EXPECT_EQ(e.code, "bad_request") << id;
    EXPECT_TRUE(e.id.is_null()) << id;
  }
}

TEST(WebMessage, unknown_and_missing_fields_and_ops) {
  const PageError unknown = error_of(R"({"t":"cmd","id":1,"op":"estop","force":true})");
  EXPECT_NE(unknown.message.find("no field 'force'"), std::string::npos) << unknown.message;
  const PageError missing = error_of(R"({"t":"cmd","id":1,"op":"jog","axis":"X"})");
  EXPECT_NE(missing.message.find("needs 'distance'"), std::string::npos) << missing.message;
  const PageError op = error_of(R"({"t":"cmd","id":1,"op":"shutdown\n\u0000now"})");
  EXPECT_EQ(op.code, "unknown_op");
  EXPECT_EQ(op.message.find('\n'), std::string::npos) << "a quoted name stays printable";
  EXPECT_EQ(error_of(R"({"t":"cmd","op":5})").code, "bad_request");
}

// Every command the page (web/src/*.js) sends decodes, with its typed fields.
TEST(WebMessage, the_pages_own_commands_decode) {
  const PageCommand check =
      command_of(R"({"t":"cmd","id":1,"op":"check","name":"a.nc","text":"G0 X1"})");
  EXPECT_EQ(check.op, PageOp::kCheck);
  EXPECT_EQ(check.text, "G0 X1");
  EXPECT_EQ(check.name, "a.nc");
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"upload","text":"M30"})").name, "program.nc");
  EXPECT_TRUE(command_of(R"({"t":"cmd","op":"start","dry_run":true})").dry_run);
  const PageCommand from =
      command_of(R"({"t":"cmd","op":"start_from","line":12,"dry_run":false,"depth_done":1.5})");
  EXPECT_EQ(from.from_line, 12);
  EXPECT_EQ(from.depth_done_mm, 1.5);
  EXPECT_FALSE(
      command_of(R"({"t":"cmd","op":"start_from","line":3,"depth_done":null})").depth_done_mm);
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"mdi","line":"G00 Z2"})").mdi_line, "G00 Z2");
  const PageCommand hold = command_of(R"({"t":"cmd","op":"jog.hold","axis":"X","velocity":-1.25})");
  EXPECT_EQ(hold.axis, "X");
  EXPECT_EQ(hold.velocity_mm_s, -1.25);
  const PageCommand touch = command_of(R"({"t":"cmd","op":"touch","target":"z","set":"G54"})");
  EXPECT_EQ(touch.target, "z");
  EXPECT_EQ(touch.set_frame, "G54");
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"ack","seq":42})").seq, 42u);
  const PageCommand jog = command_of(R"({"t":"cmd","op":"jog","axis":"X","distance":-0.01})");
  EXPECT_EQ(jog.params, (Json{{"axis", "X"}, {"distance", -0.01}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"home","axes":"Z"})").params, (Json{{"axes", "Z"}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"home"})").params, Json::object());
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"offset.set","frame":"G55","x":1})").params,
            (Json{{"frame", "G55"}, {"x", 1}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"feed.override","percent":75})").params,
            (Json{{"percent", 75}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"var.read","names":["io.z_mm","io.x_mm"]})").params,
            (Json{{"names", {"io.z_mm", "io.x_mm"}}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"var.write","name":"a.b","value":"2ms"})").params,
            (Json{{"name", "a.b"}, {"value", "2ms"}}));
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"var.force","name":"a.b","value":false})").params,
            (Json{{"name", "a.b"}, {"value", false}}));
  // The shift (shift.js): electrode.change relayed as typed, measure and queue.add typed.
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"electrode.change","electrode":"E2","kind":"tube",
                           "size_mm":1,"material":"copper","new_length_mm":300})")
                .params,
            (Json{{"electrode", "E2"},
                  {"kind", "tube"},
                  {"size_mm", 1},
                  {"material", "copper"},
                  {"new_length_mm", 300}}));
  const PageCommand measure =
      command_of(R"({"t":"cmd","op":"electrode.measure","reference":"setter"})");
  EXPECT_EQ(measure.target, "setter");
  EXPECT_EQ(measure.set_frame, "");
  const PageCommand add = command_of(
      R"({"t":"cmd","op":"queue.add","name":"r.nc","text":"M30","repeat":3,"step_x":10,"step_y":-2.5})");
  EXPECT_EQ(add.name, "r.nc");
  EXPECT_EQ(add.repeat, 3);
  EXPECT_EQ(add.step_x_mm, 10.0);
  EXPECT_EQ(add.step_y_mm, -2.5);
  EXPECT_EQ(command_of(R"({"t":"cmd","op":"jobs.get","limit":200,"csv":true})").params,
            (Json{{"limit", 200}, {"csv", true}}));
  for (const char* op :
       {"cycle.hold", "cycle.resume", "cycle.stop", "estop", "reset", "jog.release", "jog.stop",
        "offset.get", "manual.status", "job", "stats", "var.list", "electrode.get", "queue",
        "queue.clear", "queue.start", "queue.stop"}) {
    const PageCommand c = command_of(std::string(R"({"t":"cmd","op":")") + op + R"("})");
    EXPECT_EQ(page_op_info(c.op).name, op);
  }
}

TEST(WebMessage, viewer_commands_are_exactly_those_that_cannot_act) {
  for (const char* op : {"check", "stats", "var.list", "var.read", "job", "offset.get",
                         "manual.status", "electrode.get", "jobs.get", "queue"}) {
    ASSERT_NE(find_page_op(op), nullptr) << op;
    EXPECT_TRUE(find_page_op(op)->viewer) << op;
  }
  for (const char* op : {"upload",
                         "start",
                         "start_from",
                         "mdi",
                         "estop",
                         "reset",
                         "home",
                         "jog",
                         "jog.hold",
                         "jog.stop",
                         "jog.release",
                         "touch",
                         "offset.set",
                         "feed.override",
                         "ack",
                         "var.write",
                         "var.force",
                         "var.unforce",
                         "cycle.hold",
                         "cycle.resume",
                         "cycle.stop",
                         "electrode.change",
                         "electrode.measure",
                         "queue.add",
                         "queue.clear",
                         "queue.start",
                         "queue.stop"}) {
    ASSERT_NE(find_page_op(op), nullptr) << op;
    EXPECT_FALSE(find_page_op(op)->viewer) << op;
  }
}

TEST(WebMessage, quote_untrusted_keeps_printable_ascii_and_cuts) {
  EXPECT_EQ(quote_untrusted("a\nb\x01\xff"), "a?b??");
  EXPECT_EQ(quote_untrusted(std::string(40, 'x'), 32), std::string(32, 'x') + "...");
}

}  // namespace
}  // namespace edm::hmi::test
