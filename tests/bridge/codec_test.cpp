// The protocol codec: motion-block JSON round trips, the checksum, error codes, request parsing.
#include "edm/bridge/codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace edm::bridge {
namespace {

using machining::MotionBlock;
using machining::MotionKind;

MotionBlock random_block(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> x(-1e3, 1e3);
  std::uniform_int_distribution<int> k(0, machining::kMotionKindCount - 1);
  std::uniform_int_distribution<std::int32_t> n(0, 100000);
  MotionBlock b;
  b.kind = static_cast<MotionKind>(k(rng));
  b.line = n(rng);
  b.col = n(rng) % 80;
  b.target = {x(rng), x(rng), x(rng)};
  b.centre = {x(rng), 0.0, x(rng)};
  b.turns = n(rng) % 5;
  b.feed_mm_s = x(rng);
  b.condition = n(rng) % 9;
  b.z_travel_mm = x(rng);
  b.final_radius_mm = (n(rng) % 2 == 0) ? 0.0 : x(rng);
  b.dwell_s = 1e-9 * x(rng);
  b.on = n(rng) % 2 == 0;
  b.electrode_ref_mm = n(rng) % 3 == 0 ? 0.0 : 50.0 + std::abs(x(rng)) / 10.0;
  return b;
}

TEST(Codec, every_kind_round_trips_through_json_text) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 2000; ++i) {
    const MotionBlock b = random_block(rng);
    const std::string text = to_json(b).dump();
    MotionBlock back;
    std::string why;
    ASSERT_TRUE(from_json(Json::parse(text), back, why)) << why << " " << text;
    EXPECT_EQ(back, b) << text;
  }
}

TEST(Codec, default_fields_are_left_out_and_only_kind_is_required) {
  MotionBlock b;
  b.kind = MotionKind::kDwell;
  b.line = 3;
  b.dwell_s = 0.5;
  EXPECT_EQ(to_json(b).dump(), R"({"col":0,"dwell_s":0.5,"kind":"dwell","line":3})");
  MotionBlock back;
  std::string why;
  ASSERT_TRUE(from_json(Json::parse(R"({"kind":"end"})"), back, why)) << why;
  EXPECT_EQ(back, MotionBlock{});
}

TEST(Codec, bad_blocks_are_refused_naming_the_field) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"line":1})", "missing 'kind'"},
      {R"({"kind":"teleport"})", "'kind'"},
      {R"({"kind":"rapid","target":[1,2]})", "'target'"},
      {R"({"kind":"rapid","target":[1,2,"z"]})", "'target'"},
      {R"({"kind":"rapid","line":1.5})", "'line'"},
      {R"({"kind":"rapid","line":-1})", "'line'"},
      {R"({"kind":"rapid","line":4294967296})", "'line'"},
      {R"({"kind":"rapid","on":1})", "'on'"},
      {R"({"kind":"rapid","speed":1})", "unknown field 'speed'"},
      {R"([1,2])", "object"},
  };
  for (const auto& [text, expect] : cases) {
    MotionBlock b;
    std::string why;
    EXPECT_FALSE(from_json(Json::parse(text), b, why)) << text;
    EXPECT_NE(why.find(expect), std::string::npos) << text << " -> " << why;
  }
}

TEST(Codec, crc32_is_the_zlib_crc) {
  Crc32 c;
  const std::string s = "123456789";
  c.update(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  EXPECT_EQ(c.value(), 0xCBF43926u);  // the standard check value of CRC-32/ISO-HDLC
}

TEST(Codec, crc32_in_pieces_is_the_crc_of_the_whole) {
  Crc32 c;
  const std::string s = "123456789";
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(s.data());
  c.update(std::span(bytes, 4));
  c.update(std::span(bytes, 0));
  c.update(std::span(bytes + 4, s.size() - 4));
  EXPECT_EQ(c.value(), 0xCBF43926u);
  EXPECT_EQ(Crc32{}.value(), 0x00000000u);
}

TEST(Codec, program_checksum_covers_order_and_values) {
  std::mt19937_64 rng(7);
  std::vector<MotionBlock> p;
  for (int i = 0; i < 100; ++i) {
    p.push_back(random_block(rng));
  }
  const std::uint32_t a = program_checksum(p);
  std::swap(p[3], p[4]);
  EXPECT_NE(program_checksum(p), a);
  std::swap(p[3], p[4]);
  p[50].feed_mm_s = std::nextafter(p[50].feed_mm_s, 1e9);
  EXPECT_NE(program_checksum(p), a);
}

TEST(Codec, one_block_record_matches_python_struct_pack) {
  // python3 -c "import struct,zlib; print('%08x' % zlib.crc32(struct.pack('<Bii6didi7dB',
  //   4, 12, 3, 1.5, -2.0, -10.0, 0.0, 0.0, 0.0, 0, 0.25, 1, 10.6, 0, 0, 0, 0, 0.0, 0.0, 0)))"
  MotionBlock b;
  b.kind = MotionKind::kDrill;
  b.line = 12;
  b.col = 3;
  b.target = {1.5, -2.0, -10.0};
  b.feed_mm_s = 0.25;
  b.condition = 1;
  b.z_travel_mm = 10.6;
  EXPECT_EQ(format_checksum(program_checksum(std::span(&b, 1))), "0ef656b5");
  // A block of a work frame carries its electrode length: 8 more bytes, '<Bii6didi7dBd' (issue
  // 33); a block without one keeps the 130-byte record above (older clients' checksums hold).
  b.electrode_ref_mm = 289.5;
  EXPECT_EQ(format_checksum(program_checksum(std::span(&b, 1))), "be2a376e");
  MotionBlock back;
  std::string why;
  ASSERT_TRUE(from_json(to_json(b), back, why)) << why;
  EXPECT_EQ(back.electrode_ref_mm, 289.5);
  for (const char* bad :
       {R"({"kind":"rapid","electrode_ref_mm":-1})", R"({"kind":"rapid","electrode_ref_mm":1e5})",
        R"({"kind":"rapid","electrode_ref_mm":"300"})"}) {
    EXPECT_FALSE(from_json(Json::parse(bad), back, why)) << bad;
    EXPECT_NE(why.find("'electrode_ref_mm'"), std::string::npos) << bad << " -> " << why;
  }
}

TEST(Codec, checksum_text_round_trips_and_rejects_junk) {
  std::uint32_t v = 0;
  ASSERT_TRUE(parse_checksum(Json(format_checksum(0xDEADBEEFu)), v));
  EXPECT_EQ(v, 0xDEADBEEFu);
  EXPECT_EQ(format_checksum(0x1u), "00000001");
  for (const Json& bad : {Json("dead"), Json("deadbeefX"), Json("deadbeeg"), Json(123)}) {
    EXPECT_FALSE(parse_checksum(bad, v)) << bad;
  }
}

TEST(Codec, error_codes_have_stable_unique_names) {
  std::set<std::string_view> names;
  for (int i = 0; i < kErrorCodeCount; ++i) {
    const auto c = static_cast<ErrorCode>(i);
    ErrorCode back{};
    ASSERT_TRUE(error_code_from_string(to_string(c), back));
    EXPECT_EQ(back, c);
    names.insert(to_string(c));
  }
  EXPECT_EQ(names.size(), static_cast<std::size_t>(kErrorCodeCount));
  EXPECT_EQ(to_string(ErrorCode::kTooLarge), "too_large");
  ErrorCode out{};
  EXPECT_FALSE(error_code_from_string("nope", out));
}

TEST(Codec, parse_request_classifies_bad_lines) {
  ErrorCode code{};
  std::string msg;
  Json id;
  EXPECT_FALSE(parse_request("{nope", code, msg, id));
  EXPECT_EQ(code, ErrorCode::kBadJson);
  EXPECT_FALSE(parse_request("[1,2]", code, msg, id));
  EXPECT_EQ(code, ErrorCode::kBadJson);
  EXPECT_FALSE(parse_request(R"({"id":4})", code, msg, id));
  EXPECT_EQ(code, ErrorCode::kBadRequest);
  EXPECT_EQ(id, Json(4));  // the error reply can still carry the id
  EXPECT_FALSE(parse_request(R"({"id":[1],"op":"ping"})", code, msg, id));
  EXPECT_EQ(code, ErrorCode::kBadRequest);
  const auto r = parse_request(R"({"id":"a","op":"ping"})", code, msg, id);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->op, "ping");
  EXPECT_EQ(r->id, Json("a"));
}

TEST(Codec, replies_errors_and_events_have_the_documented_shape) {
  EXPECT_EQ(make_reply(7, {{"pong", true}}).dump(), R"({"id":7,"ok":true,"pong":true})");
  EXPECT_EQ(make_error(nullptr, ErrorCode::kBusy, "later").dump(),
            R"({"error":{"code":"busy","message":"later"},"ok":false})");
  EXPECT_EQ(make_event("alarm", 3, {{"code", 130}}).dump(),
            R"({"code":130,"event":"alarm","seq":3})");
  EXPECT_EQ(make_request(1, "ping").dump(), R"({"id":1,"op":"ping"})");
  // Invalid UTF-8 never throws out of to_line.
  const std::string line = to_line(Json{{"s", std::string("\xff\xfe")}});
  EXPECT_EQ(line.back(), '\n');
}

TEST(Codec, status_message_round_trips) {
  StatusMessage s;
  s.state = "RUNNING";
  s.cause = 130;
  s.t_s = 1.25;
  s.cycle = 99;
  s.job_outcome = "running";
  s.job_generation = 2;
  s.job_block = 5;
  s.job_blocks = 10;
  s.job_line = 42;
  s.vars = {{"io.z_mm", -1.5}, {"io.depth_mm", 0.5}};
  s.dropped = 3;
  StatusMessage back;
  std::string why;
  ASSERT_TRUE(from_json(Json::parse(to_json(s).dump()), back, why)) << why;
  EXPECT_EQ(back.state, s.state);
  EXPECT_EQ(back.job_line, 42);
  EXPECT_EQ(back.dropped, 3u);
  ASSERT_EQ(back.vars.size(), 2u);
  EXPECT_FALSE(from_json(Json::parse(R"({"state":"READY"})"), back, why));
}

}  // namespace
}  // namespace edm::bridge
