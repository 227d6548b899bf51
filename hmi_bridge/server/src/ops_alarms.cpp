// The alarms as the operator reads them (ops_handlers.hpp; docs/protocol.md "Alarms"):
//   the `alarm` event and the history: each alarm raised, with its source, text and value, the
//   machine time and the wall time, and the cause and remedy of its code (rt::alarm_help);
//   alarms.get: the latched (active) alarms and the history, newest last.
#include <cmath>
#include <ctime>
#include <string>

#include "edm/runtime/alarm_help.hpp"
#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {
namespace {

Json value_json(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

}  // namespace

std::string wall_time(std::chrono::system_clock::time_point t) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch());
  const std::time_t secs = static_cast<std::time_t>(ms.count() / 1000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[40];
  const std::size_t n = std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  std::snprintf(buf + n, sizeof buf - n, ".%03dZ", static_cast<int>(ms.count() % 1000));
  return buf;
}

namespace {

void add_help(Json& j, rt::AlarmCode code) {
  const rt::AlarmHelp h = rt::alarm_help(code);
  j["cause"] = std::string(h.cause);
  j["remedy"] = std::string(h.remedy);
}

}  // namespace

Json alarm_json(const rt::Alarm& a, std::chrono::system_clock::time_point wall) {
  Json j = {{"code", static_cast<int>(a.code)},
            {"name", std::string(rt::to_string(a.code))},
            {"severity", a.severity == rt::AlarmSeverity::kFault ? "fault" : "warning"},
            {"t_s", rt::to_seconds(a.time)},
            {"wall", wall_time(wall)},
            {"source", std::string(a.source)},
            {"text", std::string(a.text)},
            {"value", value_json(a.value)}};
  add_help(j, a.code);
  return j;
}

Body op_alarms_get(Session& s, const Json& /*msg*/) {
  auto& srv = s.server();
  std::array<rt::ActiveAlarm, rt::Machine::kLatchCapacity> latched{};
  const std::size_t n = srv.rt.machine().active_alarms(latched.data(), latched.size());
  Json active = Json::array();
  for (std::size_t i = 0; i < n; ++i) {
    const rt::ActiveAlarm& a = latched[i];
    Json j = {{"code", static_cast<int>(a.code)},
              {"name", std::string(rt::to_string(a.code))},
              {"source", std::string(a.source)},
              {"text", std::string(a.text)},
              {"value", value_json(a.value)},
              {"first_t_s", rt::to_seconds(a.first)},
              {"count", a.count}};
    add_help(j, a.code);
    active.push_back(std::move(j));
  }
  Json history = Json::array();
  for (const Json& h : srv.alarm_history) history.push_back(h);
  return Json{{"active", std::move(active)},
              {"history", std::move(history)},
              {"forgotten", srv.alarms_forgotten},
              {"cause", static_cast<int>(srv.rt.machine().last_cause())}};
}

}  // namespace edm::bridge::ops
