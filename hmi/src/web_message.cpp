#include "edm/hmi/web_message.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <span>

#include "edm/hmi/web_job.hpp"

namespace edm::hmi {

namespace {

using bridge::Json;

enum class Kind : std::uint8_t {
  kString,        // ≤ max bytes
  kLine,          // a string of ≤ max bytes without CR or LF
  kBool,          // true / false
  kNumber,        // finite
  kNumberOrNull,  // finite, or null (absent)
  kInt32,         // an integer within int32
  kUint,          // a non-negative integer
  kStringArray,   // ≤ kMaxPageVarNames strings of ≤ max bytes each
  kScalar,        // a finite number, true/false or a string of ≤ max bytes
};

struct Field {
  std::string_view key;
  Kind kind;
  bool required;
  std::size_t max_bytes;  // strings
  bool relay;             // copied into PageCommand::params
};

struct OpSpec {
  PageOpInfo info;
  std::span<const Field> fields;
};

constexpr std::size_t kName = kMaxPageNameBytes;
constexpr std::size_t kWord = kMaxPageWordBytes;

constexpr Field kProgramFields[] = {{"text", Kind::kString, true, kMaxWebProgramBytes, false},
                                    {"name", Kind::kString, false, kName, false}};
constexpr Field kStartFields[] = {{"dry_run", Kind::kBool, false, 0, false}};
constexpr Field kStartFromFields[] = {{"line", Kind::kInt32, true, 0, false},
                                      {"depth_done", Kind::kNumberOrNull, false, 0, false},
                                      {"dry_run", Kind::kBool, false, 0, false}};
constexpr Field kMdiFields[] = {{"line", Kind::kLine, true, kMaxPageMdiBytes, false}};
constexpr Field kOverrideFields[] = {{"percent", Kind::kNumber, true, 0, true}};
constexpr Field kHomeFields[] = {{"axes", Kind::kString, false, kWord, true}};
constexpr Field kJogFields[] = {{"axis", Kind::kString, true, kWord, true},
                                {"distance", Kind::kNumber, true, 0, true}};
constexpr Field kJogHoldFields[] = {{"axis", Kind::kString, true, kWord, false},
                                    {"velocity", Kind::kNumber, true, 0, false}};
constexpr Field kTouchFields[] = {{"target", Kind::kString, true, kWord, false},
                                  {"set", Kind::kString, false, kWord, false}};
constexpr Field kOffsetSetFields[] = {{"frame", Kind::kString, false, kWord, true},
                                      {"x", Kind::kNumber, false, 0, true},
                                      {"y", Kind::kNumber, false, 0, true},
                                      {"z", Kind::kNumber, false, 0, true}};
constexpr Field kAckFields[] = {{"seq", Kind::kUint, true, 0, false}};
constexpr Field kVarListFields[] = {{"prefix", Kind::kString, false, kName, true}};
constexpr Field kVarReadFields[] = {{"names", Kind::kStringArray, true, kName, true}};
constexpr Field kVarWriteFields[] = {{"name", Kind::kString, true, kName, true},
                                     {"value", Kind::kScalar, true, kName, true}};
constexpr Field kVarNameFields[] = {{"name", Kind::kString, true, kName, true}};
constexpr Field kElectrodeChangeFields[] = {{"electrode", Kind::kString, true, kName, true},
                                            {"kind", Kind::kString, false, kWord, true},
                                            {"size_mm", Kind::kNumber, false, 0, true},
                                            {"material", Kind::kString, false, kName, true},
                                            {"new_length_mm", Kind::kNumber, false, 0, true}};
constexpr Field kElectrodeMeasureFields[] = {{"reference", Kind::kString, true, kWord, false},
                                             {"frame", Kind::kString, false, kWord, false}};
constexpr Field kJobsGetFields[] = {{"limit", Kind::kUint, false, 0, true},
                                    {"csv", Kind::kBool, false, 0, true}};
constexpr Field kConditionSetFields[] = {{"E", Kind::kInt32, true, 0, true},
                                         {"field", Kind::kString, true, kWord, true},
                                         {"value", Kind::kNumber, true, 0, true}};
constexpr Field kQueueAddFields[] = {{"text", Kind::kString, true, kMaxWebProgramBytes, false},
                                     {"name", Kind::kString, false, kName, false},
                                     {"repeat", Kind::kInt32, false, 0, false},
                                     {"step_x", Kind::kNumber, false, 0, false},
                                     {"step_y", Kind::kNumber, false, 0, false}};
constexpr std::span<const Field> kNone{};

using L = PageLane;
constexpr std::array<OpSpec, 38> kOps{{
    {{"check", PageOp::kCheck, true, L::kProgram}, kProgramFields},
    {{"upload", PageOp::kUpload, false, L::kProgram}, kProgramFields},
    {{"start", PageOp::kStart, false, L::kMachine}, kStartFields},
    {{"start_from", PageOp::kStartFrom, false, L::kProgram}, kStartFromFields},
    {{"mdi", PageOp::kMdi, false, L::kProgram}, kMdiFields},
    {{"cycle.hold", PageOp::kCycleHold, false, L::kMachine}, kNone},
    {{"cycle.resume", PageOp::kCycleResume, false, L::kMachine}, kNone},
    {{"cycle.stop", PageOp::kCycleStop, false, L::kMachine}, kNone},
    {{"estop", PageOp::kEstop, false, L::kMachine}, kNone},
    {{"reset", PageOp::kReset, false, L::kMachine}, kNone},
    {{"feed.override", PageOp::kFeedOverride, false, L::kMachine}, kOverrideFields},
    {{"home", PageOp::kHome, false, L::kMachine}, kHomeFields},
    {{"jog", PageOp::kJog, false, L::kMachine}, kJogFields},
    {{"jog.hold", PageOp::kJogHold, false, L::kMachine}, kJogHoldFields},
    {{"jog.release", PageOp::kJogRelease, false, L::kInline}, kNone},
    {{"jog.stop", PageOp::kJogStop, false, L::kMachine}, kNone},
    {{"touch", PageOp::kTouch, false, L::kMachine}, kTouchFields},
    {{"offset.get", PageOp::kOffsetGet, true, L::kInline}, kNone},
    {{"offset.set", PageOp::kOffsetSet, false, L::kMachine}, kOffsetSetFields},
    {{"manual.status", PageOp::kManualStatus, true, L::kInline}, kNone},
    {{"ack", PageOp::kAck, false, L::kInline}, kAckFields},
    {{"job", PageOp::kJob, true, L::kProgram}, kNone},
    {{"stats", PageOp::kStats, true, L::kProgram}, kNone},
    {{"var.list", PageOp::kVarList, true, L::kProgram}, kVarListFields},
    {{"var.read", PageOp::kVarRead, true, L::kProgram}, kVarReadFields},
    {{"var.write", PageOp::kVarWrite, false, L::kProgram}, kVarWriteFields},
    {{"var.force", PageOp::kVarForce, false, L::kProgram}, kVarWriteFields},
    {{"var.unforce", PageOp::kVarUnforce, false, L::kProgram}, kVarNameFields},
    {{"electrode.get", PageOp::kElectrodeGet, true, L::kProgram}, kNone},
    {{"electrode.change", PageOp::kElectrodeChange, false, L::kMachine}, kElectrodeChangeFields},
    {{"electrode.measure", PageOp::kElectrodeMeasure, false, L::kMachine}, kElectrodeMeasureFields},
    {{"jobs.get", PageOp::kJobsGet, true, L::kProgram}, kJobsGetFields},
    {{"queue", PageOp::kQueue, true, L::kInline}, kNone},
    {{"queue.add", PageOp::kQueueAdd, false, L::kProgram}, kQueueAddFields},
    {{"queue.clear", PageOp::kQueueClear, false, L::kInline}, kNone},
    {{"queue.start", PageOp::kQueueStart, false, L::kInline}, kNone},
    {{"queue.stop", PageOp::kQueueStop, false, L::kInline}, kNone},
    {{"condition.set", PageOp::kConditionSet, false, L::kProgram}, kConditionSetFields},
}};

constexpr bool ops_in_enum_order() {
  for (std::size_t i = 0; i < kOps.size(); ++i) {
    if (static_cast<std::size_t>(kOps[i].info.op) != i) return false;
  }
  return true;
}
static_assert(ops_in_enum_order(), "kOps must list every PageOp in its enum order");

const OpSpec* find_spec(std::string_view name) noexcept {
  for (const OpSpec& s : kOps) {
    if (s.info.name == name) return &s;
  }
  return nullptr;
}

bool finite(const Json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

bool short_string(const Json& v, std::size_t max) {
  return v.is_string() && v.get_ref<const std::string&>().size() <= max;
}

bool fits(const Json& v, const Field& f) {
  switch (f.kind) {
    case Kind::kString: return short_string(v, f.max_bytes);
    case Kind::kLine:
      return short_string(v, f.max_bytes) &&
             v.get_ref<const std::string&>().find_first_of("\r\n") == std::string::npos;
    case Kind::kBool: return v.is_boolean();
    case Kind::kNumber: return finite(v);
    case Kind::kNumberOrNull: return v.is_null() || finite(v);
    case Kind::kInt32:
      if (v.is_number_unsigned()) {
        return v.get<std::uint64_t>() <=
               static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max());
      }
      return v.is_number_integer() &&
             v.get<std::int64_t>() >= std::numeric_limits<std::int32_t>::min() &&
             v.get<std::int64_t>() <= std::numeric_limits<std::int32_t>::max();
    case Kind::kUint:
      return v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0);
    case Kind::kStringArray:
      if (!v.is_array() || v.empty() || v.size() > kMaxPageVarNames) return false;
      for (const Json& e : v) {
        if (!short_string(e, f.max_bytes)) return false;
      }
      return true;
    case Kind::kScalar: return finite(v) || v.is_boolean() || short_string(v, f.max_bytes);
  }
  return false;
}

std::string expected(const Field& f) {
  const std::string bytes = std::to_string(f.max_bytes);
  switch (f.kind) {
    case Kind::kString: return "a string of at most " + bytes + " bytes";
    case Kind::kLine: return "one line of at most " + bytes + " bytes";
    case Kind::kBool: return "true or false";
    case Kind::kNumber: return "a finite number";
    case Kind::kNumberOrNull: return "a finite number or null";
    case Kind::kInt32: return "a 32-bit integer";
    case Kind::kUint: return "a non-negative integer";
    case Kind::kStringArray:
      return "an array of 1 to " + std::to_string(kMaxPageVarNames) + " strings of at most " +
             bytes + " bytes";
    case Kind::kScalar: return "a number, true/false or a string of at most " + bytes + " bytes";
  }
  return "?";
}

PageError error(std::string code, std::string message) {
  return PageError{std::move(code), std::move(message), nullptr, false};
}

PageError command_error(const Json& id, std::string message) {
  return PageError{"bad_request", std::move(message), id, true};
}

/// The command's typed fields from its checked JSON.
void fill(PageCommand& c, const Json& m) {
  const auto str = [&m](const char* k, std::string& out) {
    if (const auto it = m.find(k); it != m.end()) out = it->get<std::string>();
  };
  const auto flag = [&m](const char* k) {
    const auto it = m.find(k);
    return it != m.end() && it->get<bool>();
  };
  switch (c.op) {
    case PageOp::kCheck:
    case PageOp::kUpload:
    case PageOp::kQueueAdd:
      str("text", c.text);
      str("name", c.name);
      if (const auto it = m.find("repeat"); it != m.end()) c.repeat = it->get<std::int32_t>();
      if (const auto it = m.find("step_x"); it != m.end()) c.step_x_mm = it->get<double>();
      if (const auto it = m.find("step_y"); it != m.end()) c.step_y_mm = it->get<double>();
      break;
    case PageOp::kElectrodeMeasure:
      str("reference", c.target);
      str("frame", c.set_frame);
      break;
    case PageOp::kStart: c.dry_run = flag("dry_run"); break;
    case PageOp::kStartFrom:
      c.from_line = m.at("line").get<std::int32_t>();
      if (const auto it = m.find("depth_done"); it != m.end() && !it->is_null()) {
        c.depth_done_mm = it->get<double>();
      }
      c.dry_run = flag("dry_run");
      break;
    case PageOp::kMdi: str("line", c.mdi_line); break;
    case PageOp::kJogHold:
      str("axis", c.axis);
      c.velocity_mm_s = m.at("velocity").get<double>();
      break;
    case PageOp::kTouch:
      str("target", c.target);
      str("set", c.set_frame);
      break;
    case PageOp::kAck: c.seq = m.at("seq").get<std::uint64_t>(); break;
    default: break;
  }
}

PageMessage decode_command(const Json& m) {
  Json id = nullptr;
  if (const auto it = m.find("id"); it != m.end()) {
    if (!it->is_number_integer() && !short_string(*it, kMaxPageIdBytes)) {
      return command_error(nullptr, "'id' must be an integer or a string of at most " +
                                        std::to_string(kMaxPageIdBytes) + " bytes");
    }
    id = *it;
  }
  const auto op = m.find("op");
  if (op == m.end() || !op->is_string()) return command_error(id, "'op' must be a string");
  const OpSpec* spec = find_spec(op->get_ref<const std::string&>());
  if (spec == nullptr) {
    PageError e = command_error(
        id, "unknown command '" + quote_untrusted(op->get_ref<const std::string&>()) + "'");
    e.code = "unknown_op";
    return e;
  }
  PageCommand c;
  c.id = id;
  c.op = spec->info.op;
  for (const auto& [key, value] : m.items()) {
    if (key == "t" || key == "id" || key == "op") continue;
    const Field* f = nullptr;
    for (const Field& candidate : spec->fields) {
      if (candidate.key == key) f = &candidate;
    }
    if (f == nullptr) {
      return command_error(
          id, "'" + std::string(spec->info.name) + "' has no field '" + quote_untrusted(key) + "'");
    }
    if (!fits(value, *f)) {
      return command_error(id, "'" + std::string(f->key) + "' must be " + expected(*f));
    }
    if (f->relay) c.params[std::string(f->key)] = value;
  }
  for (const Field& f : spec->fields) {
    if (f.required && !m.contains(f.key)) {
      return command_error(
          id, "'" + std::string(spec->info.name) + "' needs '" + std::string(f.key) + "'");
    }
  }
  fill(c, m);
  return c;
}

PageMessage decode(std::string_view text) {
  Json m;
  std::string why;
  if (!bridge::parse_json_strict(text, m, why)) return error("bad_json", why);
  if (!m.is_object()) return error("bad_json", "a message must be a JSON object");
  const auto t = m.find("t");
  if (t == m.end() || !t->is_string())
    return error("bad_request", "a message needs a string \"t\"");
  const std::string& type = t->get_ref<const std::string&>();
  if (type == "cmd") return decode_command(m);
  if (type == "held") {
    if (m.size() != 1) return error("bad_request", "\"held\" has no fields");
    return PageHeld{};
  }
  if (type == "login") {
    const auto token = m.find("token");
    if (m.size() != 2 || token == m.end() || !short_string(*token, kMaxPageTokenBytes)) {
      return error("bad_request", "\"login\" needs only \"token\", a string of at most " +
                                      std::to_string(kMaxPageTokenBytes) + " bytes");
    }
    return PageLogin{token->get<std::string>()};
  }
  return error("bad_request", "unknown message type '" + quote_untrusted(type) + "'");
}

}  // namespace

const PageOpInfo* find_page_op(std::string_view name) noexcept {
  const OpSpec* s = find_spec(name);
  return s == nullptr ? nullptr : &s->info;
}

const PageOpInfo& page_op_info(PageOp op) noexcept {
  return kOps[static_cast<std::size_t>(op)].info;
}

PageMessage decode_page_message(std::string_view text) noexcept {
  try {
    return decode(text);
  } catch (const std::exception&) {  // bad_alloc, or a bug: an error, never an escape
    try {
      return error("bad_request", "message not understood");
    } catch (...) {
      return PageError{};
    }
  }
}

std::string quote_untrusted(std::string_view s, std::size_t max) {
  std::string out;
  const std::size_t n = std::min(s.size(), max);
  out.reserve(n + 3);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    out.push_back(c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?');
  }
  if (s.size() > max) out += "...";
  return out;
}

}  // namespace edm::hmi
