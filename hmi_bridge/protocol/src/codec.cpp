#include "edm/bridge/codec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <unordered_set>

namespace edm::bridge {

using machining::MotionBlock;
using machining::MotionKind;
using machining::Vec3;

namespace {

Json vec_to_json(const Vec3& v) { return Json::array({v.x, v.y, v.z}); }

// The sparse form of a block: a field is written only where it differs from MotionBlock{}.
template <class T, class ToJson = std::identity>
void put_unless_default(Json& j, const char* key, const T& v, const T& dflt, ToJson to_json = {}) {
  if (v != dflt) {
    j[key] = to_json(v);
  }
}

bool finite_number(const Json& j, double& out) {
  if (!j.is_number()) {
    return false;
  }
  out = j.get<double>();
  return std::isfinite(out);
}

bool int32_value(const Json& j, std::int32_t& out) {
  if (!j.is_number_integer()) {
    return false;
  }
  if (j.is_number_unsigned()) {
    const auto u = j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      return false;
    }
    out = static_cast<std::int32_t>(u);
    return true;
  }
  const auto v = j.get<std::int64_t>();
  if (v < std::numeric_limits<std::int32_t>::min() ||
      v > std::numeric_limits<std::int32_t>::max()) {
    return false;
  }
  out = static_cast<std::int32_t>(v);
  return true;
}

bool vec_from_json(const Json& j, Vec3& out) {
  if (!j.is_array() || j.size() != 3) {
    return false;
  }
  return finite_number(j[0], out.x) && finite_number(j[1], out.y) && finite_number(j[2], out.z);
}

// Little-endian writers for the canonical block record.
template <class T>
void put_le(std::uint8_t*& p, T v) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  const U u = std::bit_cast<U>(v);
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    *p++ = static_cast<std::uint8_t>(u >> (8 * i));
  }
}

}  // namespace

Json to_json(const MotionBlock& b) {
  const MotionBlock d{};
  Json j = Json::object();
  j["kind"] = std::string(machining::to_string(b.kind));
  j["line"] = b.line;
  j["col"] = b.col;
  put_unless_default(j, "target", b.target, d.target, vec_to_json);
  put_unless_default(j, "centre", b.centre, d.centre, vec_to_json);
  put_unless_default(j, "turns", b.turns, d.turns);
  put_unless_default(j, "feed_mm_s", b.feed_mm_s, d.feed_mm_s);
  put_unless_default(j, "condition", b.condition, d.condition);
  put_unless_default(j, "z_travel_mm", b.z_travel_mm, d.z_travel_mm);
  put_unless_default(j, "depth_mm", b.depth_mm, d.depth_mm);
  put_unless_default(j, "depth_done_mm", b.depth_done_mm, d.depth_done_mm);
  put_unless_default(j, "resume_touch_z_mm", b.resume_touch_z_mm, d.resume_touch_z_mm);
  put_unless_default(j, "resume_wear_mm", b.resume_wear_mm, d.resume_wear_mm);
  put_unless_default(j, "final_radius_mm", b.final_radius_mm, d.final_radius_mm);
  put_unless_default(j, "dwell_s", b.dwell_s, d.dwell_s);
  put_unless_default(j, "on", b.on, d.on);
  put_unless_default(j, "cut", b.cut, d.cut);
  put_unless_default(j, "electrode_ref_mm", b.electrode_ref_mm, d.electrode_ref_mm);
  return j;
}

bool from_json(const Json& j, MotionBlock& out, std::string& error) {
  if (!j.is_object()) {
    error = "a block must be an object";
    return false;
  }
  MotionBlock b{};
  bool has_kind = false;
  for (const auto& [key, v] : j.items()) {
    bool ok = true;
    if (key == "kind") {
      ok = v.is_string() &&
           machining::motion_kind_from_string(v.get_ref<const std::string&>(), b.kind);
      has_kind = ok;
    } else if (key == "line") {
      ok = int32_value(v, b.line) && b.line >= 0;
    } else if (key == "col") {
      ok = int32_value(v, b.col) && b.col >= 0;
    } else if (key == "target") {
      ok = vec_from_json(v, b.target);
    } else if (key == "centre") {
      ok = vec_from_json(v, b.centre);
    } else if (key == "turns") {
      ok = int32_value(v, b.turns) && b.turns >= 0;
    } else if (key == "feed_mm_s") {
      ok = finite_number(v, b.feed_mm_s);
    } else if (key == "condition") {
      ok = int32_value(v, b.condition);
    } else if (key == "z_travel_mm") {
      ok = finite_number(v, b.z_travel_mm);
    } else if (key == "depth_mm") {
      ok = finite_number(v, b.depth_mm) && b.depth_mm >= 0.0;
    } else if (key == "depth_done_mm") {
      ok = finite_number(v, b.depth_done_mm) && b.depth_done_mm >= 0.0;
    } else if (key == "resume_touch_z_mm") {
      ok = finite_number(v, b.resume_touch_z_mm);
    } else if (key == "resume_wear_mm") {
      ok = finite_number(v, b.resume_wear_mm) && b.resume_wear_mm >= 0.0;
    } else if (key == "final_radius_mm") {
      ok = finite_number(v, b.final_radius_mm);
    } else if (key == "dwell_s") {
      ok = finite_number(v, b.dwell_s);
    } else if (key == "electrode_ref_mm") {
      ok = finite_number(v, b.electrode_ref_mm) && b.electrode_ref_mm >= 0.0 &&
           b.electrode_ref_mm <= 1e4;
    } else if (key == "on") {
      ok = v.is_boolean();
      if (ok) {
        b.on = v.get<bool>();
      }
    } else if (key == "cut") {
      ok = v.is_boolean();
      if (ok) {
        b.cut = v.get<bool>();
      }
    } else {
      error = "unknown field '" + key + "'";
      return false;
    }
    if (!ok) {
      error = "bad value for '" + key + "'";
      return false;
    }
  }
  if (!has_kind) {
    error = "missing 'kind'";
    return false;
  }
  out = b;
  return true;
}

void Crc32::update(std::span<const std::uint8_t> bytes) noexcept {
  crc_.process_bytes(bytes.data(), bytes.size());
}

void Crc32::update(const MotionBlock& b) noexcept {
  std::array<std::uint8_t, kBlockRecordBytes + sizeof(double) + 1> rec{};
  std::uint8_t* p = rec.data();
  *p++ = static_cast<std::uint8_t>(b.kind);
  put_le(p, b.line);
  put_le(p, b.col);
  for (const Vec3* v : {&b.target, &b.centre}) {
    put_le(p, v->x);
    put_le(p, v->y);
    put_le(p, v->z);
  }
  put_le(p, b.turns);
  put_le(p, b.feed_mm_s);
  put_le(p, b.condition);
  put_le(p, b.z_travel_mm);
  put_le(p, b.depth_mm);
  put_le(p, b.depth_done_mm);
  put_le(p, b.resume_touch_z_mm);
  put_le(p, b.resume_wear_mm);
  put_le(p, b.final_radius_mm);
  put_le(p, b.dwell_s);
  *p++ = b.on ? 1 : 0;
  // The electrode length of a block in a work frame follows, when there is one: a client that
  // never sends it (before issue 33) keeps its 130-byte records.
  // So does a wire cut's flag (issue 34), only when set: a drill's records stay as they were.
  if (b.electrode_ref_mm != 0.0) put_le(p, b.electrode_ref_mm);
  if (b.cut) *p++ = 1;
  update(std::span<const std::uint8_t>(rec.data(), static_cast<std::size_t>(p - rec.data())));
}

std::uint32_t program_checksum(std::span<const MotionBlock> blocks) noexcept {
  Crc32 crc;
  for (const auto& b : blocks) {
    crc.update(b);
  }
  return crc.value();
}

std::string format_checksum(std::uint32_t crc) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s(8, '0');
  for (int i = 7; i >= 0; --i) {
    s[static_cast<std::size_t>(i)] = kHex[crc & 0xFu];
    crc >>= 4;
  }
  return s;
}

bool parse_checksum(const Json& j, std::uint32_t& out) noexcept {
  if (!j.is_string()) {
    return false;
  }
  const auto& s = j.get_ref<const std::string&>();
  if (s.size() != 8) {
    return false;
  }
  std::uint32_t v = 0;
  for (const char c : s) {
    std::uint32_t d = 0;
    if (c >= '0' && c <= '9') {
      d = static_cast<std::uint32_t>(c - '0');
    } else if (c >= 'a' && c <= 'f') {
      d = static_cast<std::uint32_t>(c - 'a' + 10);
    } else if (c >= 'A' && c <= 'F') {
      d = static_cast<std::uint32_t>(c - 'A' + 10);
    } else {
      return false;
    }
    v = (v << 4) | d;
  }
  out = v;
  return true;
}

Json make_request(std::int64_t id, std::string_view op, const Json& params) {
  Json j = params.is_object() ? params : Json::object();
  j["id"] = id;
  j["op"] = std::string(op);
  return j;
}

Json hello_params(std::string_view token, std::string_view peer) {
  Json j = {{"protocol", kProtocolVersion}, {"token", std::string(token)}};
  if (!peer.empty()) j["peer"] = std::string(peer);
  return j;
}

Json make_reply(const Json& id, const Json& body) {
  Json j = body.is_object() ? body : Json::object();
  if (!id.is_null()) {
    j["id"] = id;
  }
  j["ok"] = true;
  return j;
}

Json make_error(const Json& id, ErrorCode code, std::string_view message, const Json& details) {
  Json err = {{"code", std::string(to_string(code))}, {"message", std::string(message)}};
  if (!details.is_null()) {
    err["details"] = details;
  }
  Json j = Json::object();
  if (!id.is_null()) {
    j["id"] = id;
  }
  j["ok"] = false;
  j["error"] = std::move(err);
  return j;
}

Json make_event(std::string_view name, std::uint64_t seq, const Json& body) {
  Json j = body.is_object() ? body : Json::object();
  j["event"] = std::string(name);
  j["seq"] = seq;
  return j;
}

namespace {

/// True when `text` nests arrays and objects deeper than `max_depth` (string contents skipped).
/// Exact for valid JSON; for invalid text it only has to be conservative enough that the parser
/// never sees deeper nesting than this admits.
bool nesting_exceeds(std::string_view text, int max_depth) noexcept {
  int depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        return true;
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return false;
}

}  // namespace

bool parse_json_strict(std::string_view text, Json& out, std::string& error) {
  if (nesting_exceeds(text, kMaxJsonDepth)) {
    error = "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    return false;
  }
  // Keys seen in each open object, innermost last (depth is bounded above).
  std::vector<std::unordered_set<std::string>> keys;
  bool duplicate = false;
  const Json::parser_callback_t cb = [&](int /*depth*/, Json::parse_event_t ev, Json& parsed) {
    if (ev == Json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (ev == Json::parse_event_t::object_end && !keys.empty()) {
      keys.pop_back();
    } else if (ev == Json::parse_event_t::key && !keys.empty() && parsed.is_string()) {
      duplicate = !keys.back().insert(parsed.get<std::string>()).second || duplicate;
    }
    return true;
  };
  Json j = Json::parse(text.begin(), text.end(), cb, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    error = "not valid JSON";
    return false;
  }
  if (duplicate) {
    error = "duplicate key in an object";
    return false;
  }
  out = std::move(j);
  return true;
}

std::optional<ParsedRequest> parse_request(std::string_view line, ErrorCode& code,
                                           std::string& message, Json& id_if_known) {
  id_if_known = nullptr;
  Json j;
  if (!parse_json_strict(line, j, message)) {
    code = ErrorCode::kBadJson;
    return std::nullopt;
  }
  if (!j.is_object()) {
    code = ErrorCode::kBadJson;
    message = "a request must be a JSON object";
    return std::nullopt;
  }
  ParsedRequest r;
  if (auto it = j.find("id"); it != j.end()) {
    if (!it->is_number_integer() && !it->is_string()) {
      code = ErrorCode::kBadRequest;
      message = "'id' must be an integer or a string";
      return std::nullopt;
    }
    r.id = *it;
    id_if_known = *it;
  }
  auto op = j.find("op");
  if (op == j.end() || !op->is_string()) {
    code = ErrorCode::kBadRequest;
    message = "missing or non-string 'op'";
    return std::nullopt;
  }
  r.op = op->get<std::string>();
  r.msg = std::move(j);
  return r;
}

std::string to_line(const Json& j) {
  std::string s = j.dump(-1, ' ', false, Json::error_handler_t::replace);
  s.push_back('\n');
  return s;
}

Json to_json(const StatusMessage& s) {
  Json vars = Json::object();
  for (const auto& [name, value] : s.vars) {
    vars[name] = std::isfinite(value) ? Json(value) : Json(nullptr);
  }
  Json job = {{"outcome", s.job_outcome}, {"generation", s.job_generation},
              {"block", s.job_block},     {"blocks", s.job_blocks},
              {"line", s.job_line},       {"jobs_started", s.job_jobs_started},
              {"slot", s.job_slot}};
  if (s.job_last) {
    Json last = {
        {"outcome", s.job_last->outcome}, {"block", s.job_last->block}, {"line", s.job_last->line}};
    for (auto [key, v] :
         {std::pair<const char*, const std::optional<double>*>{"depth_mm", &s.job_last->depth_mm},
          {"touch_z_mm", &s.job_last->touch_z_mm},
          {"wear_mm", &s.job_last->wear_mm}}) {
      if (*v && std::isfinite(**v)) last[key] = **v;
    }
    job["last"] = std::move(last);
  }
  return {{"state", s.state},    {"cause", s.cause},      {"t_s", s.t_s},
          {"cycle", s.cycle},    {"job", std::move(job)}, {"vars", std::move(vars)},
          {"dropped", s.dropped}};
}

bool from_json(const Json& j, StatusMessage& out, std::string& error) {
  try {
    StatusMessage s;
    s.state = j.at("state").get<std::string>();
    s.cause = j.at("cause").get<int>();
    s.t_s = j.at("t_s").get<double>();
    s.cycle = j.at("cycle").get<std::uint64_t>();
    const Json& job = j.at("job");
    s.job_outcome = job.at("outcome").get<std::string>();
    s.job_generation = job.at("generation").get<std::uint64_t>();
    s.job_block = job.at("block").get<std::uint64_t>();
    s.job_blocks = job.at("blocks").get<std::uint64_t>();
    s.job_line = job.at("line").get<std::int32_t>();
    s.job_jobs_started = job.value("jobs_started", std::uint64_t{0});  // absent: older runtime
    s.job_slot = job.value("slot", std::string("main"));
    if (auto it = job.find("last"); it != job.end() && it->is_object()) {
      LastJob l;
      l.outcome = it->at("outcome").get<std::string>();
      l.block = it->at("block").get<std::uint64_t>();
      l.line = it->at("line").get<std::int32_t>();
      for (auto [key, v] : {std::pair<const char*, std::optional<double>*>{"depth_mm", &l.depth_mm},
                            {"touch_z_mm", &l.touch_z_mm},
                            {"wear_mm", &l.wear_mm}}) {
        if (auto d = it->find(key); d != it->end() && d->is_number()) *v = d->get<double>();
      }
      s.job_last = std::move(l);
    }
    for (const auto& [name, v] : j.at("vars").items()) {
      s.vars.emplace_back(
          name, v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN());
    }
    if (auto it = j.find("dropped"); it != j.end()) {
      s.dropped = it->get<std::uint64_t>();
    }
    out = std::move(s);
    return true;
  } catch (const Json::exception& e) {
    error = e.what();
    return false;
  }
}

}  // namespace edm::bridge
