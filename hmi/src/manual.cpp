// The client side of home, jog, touch-off and work offsets (manual.hpp).
#include "edm/hmi/manual.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <thread>

namespace edm::hmi {

namespace {

using bridge::Json;
using Clock = std::chrono::steady_clock;

std::optional<double> finite(const Json& obj, const char* key) {
  const auto it = obj.find(key);
  if (it == obj.end() || !it->is_number()) return std::nullopt;
  const double v = it->get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

}  // namespace

bool manual_status_from_json(const Json& j, ManualStatus& out, std::string& error) {
  try {
    ManualStatus s;
    s.mode = j.value("mode", std::string());
    s.busy = j.value("busy", false);
    if (const auto seen = j.find("seen_seq"); seen != j.end()) {
      s.seen_seq = seen->get<std::uint64_t>();
    }
    if (const auto ref = j.find("referenced"); ref != j.end() && ref->is_object()) {
      for (std::size_t i = 0; i < 3; ++i) {
        const std::string axis(1, "XYZ"[i]);
        if (const auto a = ref->find(axis); a != ref->end()) s.referenced[i] = a->get<bool>();
      }
    }
    if (const auto res = j.find("result"); res != j.end() && res->is_object()) {
      ManualResult r;
      r.seq = res->value("seq", std::uint64_t{0});
      r.op = res->value("op", std::string());
      r.target = res->value("target", std::string());
      r.ok = res->value("ok", false);
      r.error = res->value("error", std::string());
      r.x_mm = finite(*res, "x");
      r.y_mm = finite(*res, "y");
      r.z_mm = finite(*res, "z");
      if (r.target == "center") r.size_mm = finite(*res, "size");
      s.result = std::move(r);
    }
    out = std::move(s);
    return true;
  } catch (const Json::exception& e) {
    error = e.what();
    return false;
  }
}

std::string normalise_axes(std::string_view text, std::string& error) {
  error.clear();
  if (text.empty()) {
    error = "no axes: give some of X, Y and Z (or none at all for every axis)";
    return {};
  }
  std::string axes;
  for (const char c : text) {
    const auto u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (u != 'X' && u != 'Y' && u != 'Z') {
      error = "'" + std::string(text) + "': axes are X, Y and Z";
      return {};
    }
    if (axes.find(u) != std::string::npos) {
      error = "'" + std::string(text) + "': axis " + std::string(1, u) + " twice";
      return {};
    }
    axes += u;
  }
  return axes;
}

std::optional<char> parse_axis(std::string_view text) {
  if (text.size() != 1) return std::nullopt;
  const auto u = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  if (u != 'X' && u != 'Y' && u != 'Z') return std::nullopt;
  return u;
}

bool valid_jog_distance(double mm) noexcept {
  const double a = std::fabs(mm);
  return std::isfinite(mm) && a >= kJogMinMm && a <= kJogMaxMm;
}

namespace {

constexpr std::pair<TouchTarget, std::string_view> kTargets[] = {
    {TouchTarget::kZ, "z"},      {TouchTarget::kXPlus, "x+"},  {TouchTarget::kXMinus, "x-"},
    {TouchTarget::kYPlus, "y+"}, {TouchTarget::kYMinus, "y-"}, {TouchTarget::kCenter, "center"},
};

}  // namespace

std::optional<TouchTarget> parse_touch_target(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const auto& [t, name] : kTargets) {
    if (lower == name) return t;
  }
  return std::nullopt;
}

std::string_view to_string(TouchTarget t) noexcept {
  for (const auto& [k, name] : kTargets) {
    if (k == t) return name;
  }
  return "?";
}

std::optional<Json> offset_set_for_touch(std::string_view frame, TouchTarget t,
                                         const ManualResult& r) {
  Json p = {{"frame", std::string(frame)}};
  auto put = [&p](const char* key, const std::optional<double>& v) {
    if (!v) return false;
    p[key] = *v;
    return true;
  };
  switch (t) {
    case TouchTarget::kZ: return put("z", r.z_mm) ? std::optional<Json>(p) : std::nullopt;
    case TouchTarget::kXPlus:
    case TouchTarget::kXMinus: return put("x", r.x_mm) ? std::optional<Json>(p) : std::nullopt;
    case TouchTarget::kYPlus:
    case TouchTarget::kYMinus: return put("y", r.y_mm) ? std::optional<Json>(p) : std::nullopt;
    case TouchTarget::kCenter:
      return put("x", r.x_mm) && put("y", r.y_mm) ? std::optional<Json>(p) : std::nullopt;
  }
  return std::nullopt;
}

std::string format_manual_result(const ManualResult& r) {
  std::string s = r.op.empty() ? std::string("manual operation") : r.op;
  if (!r.target.empty()) s += " " + r.target;
  if (r.ok) {
    s += " ok";
  } else if (r.error == kStoppedByOperator) {
    s += " " + r.error;  // the expected end of a continuous jog, not a failure
  } else {
    s += " failed";
    if (!r.error.empty()) s += ": " + r.error;
  }
  char buf[48];
  if (r.op != "touch") return s;  // only a touch's coordinates are a result (the place found)
  for (auto [name, v] :
       {std::pair{"X", &r.x_mm}, std::pair{"Y", &r.y_mm}, std::pair{"Z", &r.z_mm}}) {
    if (!*v) continue;
    std::snprintf(buf, sizeof buf, " %s %.4f", name, std::fabs(**v) < 5e-5 ? 0.0 : **v);
    s += buf;
  }
  if (r.x_mm || r.y_mm || r.z_mm) s += " (machine)";
  if (r.size_mm) {
    std::snprintf(buf, sizeof buf, ", bore diameter %.4f", *r.size_mm);
    s += buf;
  }
  return s;
}

bool manual_done(const ManualStatus& s, std::uint64_t seq, std::uint64_t result_from) noexcept {
  return !s.busy && (!s.seen_seq || *s.seen_seq >= seq) && s.result && s.result->seq >= result_from;
}

ManualWait wait_manual(bridge::Client& client, std::uint64_t seq, std::uint64_t result_from,
                       const std::atomic<bool>& interrupt, std::chrono::milliseconds period,
                       std::chrono::milliseconds timeout) {
  ManualWait w;
  const Clock::time_point deadline = Clock::now() + timeout;
  for (;;) {
    if (interrupt.load()) {
      w.interrupted = true;
      return w;
    }
    const bridge::Reply r = client.request("manual.status");
    if (!r) {
      w.error = "manual.status: " +
                (r.code ? std::string(bridge::to_string(*r.code)) + ": " : std::string()) +
                r.message;
      return w;
    }
    std::string error;
    if (!manual_status_from_json(r.body, w.status, error)) {
      w.error = "manual.status: malformed reply: " + error;
      return w;
    }
    if (manual_done(w.status, seq, result_from)) {
      w.done = true;
      return w;
    }
    if (Clock::now() >= deadline) {
      w.error = "the operation did not end within " +
                std::to_string(std::chrono::duration_cast<std::chrono::seconds>(timeout).count()) +
                " s";
      return w;
    }
    std::this_thread::sleep_for(period);  // the polling interval the protocol asks for
  }
}

std::chrono::milliseconds jog_refresh_period(double deadman_ms) noexcept {
  const double p = std::isfinite(deadman_ms) ? deadman_ms / 3.0 : 10.0;
  return std::chrono::milliseconds(static_cast<long long>(std::max(10.0, std::floor(p))));
}

}  // namespace edm::hmi
