// edmhmi alarms [--all] — the active alarms, each with its source, why, the value that tripped
// it, the machine time, the cause and the remedy; --all adds the history since edmplc started
// (alarms.get, docs/hmi.md "Alarms"). `edmhmi status` prints the active ones the same way.
#include <cstdio>
#include <string>

#include "cli.hpp"

namespace edmhmi {
namespace {

using edm::bridge::Json;

std::string value_text(const Json& a) {
  const auto v = a.find("value");
  if (v == a.end() || !v->is_number()) return "";
  char buf[48];
  std::snprintf(buf, sizeof buf, " [value %.6g]", v->get<double>());
  return buf;
}

void print_alarm(const Json& a, const char* time_key) {
  std::printf("  %d %s from %s at t=%.3f s%s%s: %s%s\n", a.value("code", 0),
              a.value("name", std::string("?")).c_str(), a.value("source", std::string()).c_str(),
              a.value(time_key, 0.0), a.contains("wall") ? " " : "",
              a.value("wall", std::string()).c_str(), a.value("text", std::string()).c_str(),
              value_text(a).c_str());
  std::printf("      cause:  %s\n      remedy: %s\n", a.value("cause", std::string()).c_str(),
              a.value("remedy", std::string()).c_str());
}

void print_active(const Json& body) {
  const Json active = body.value("active", Json::array());
  if (active.empty()) {
    std::printf("alarms: none active\n");
    return;
  }
  std::printf("alarms: %zu active\n", active.size());
  for (const Json& a : active) print_alarm(a, "first_t_s");
}

}  // namespace

bool print_active_alarms(edm::bridge::Client& client) {
  const edm::bridge::Reply r = client.request("alarms.get");
  if (!r) {
    report_error("alarms.get", r);
    return false;
  }
  print_active(r.body);
  return true;
}

int cmd_alarms(bool all, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const edm::bridge::Reply r = client.request("alarms.get");
  if (!r) return report_error("alarms.get", r);
  print_active(r.body);
  if (!all) return kExitOk;
  const Json history = r.body.value("history", Json::array());
  std::printf("history: %zu alarm(s) since edmplc started", history.size());
  if (const auto f = r.body.value("forgotten", 0ULL); f > 0)
    std::printf(" (%llu older ones dropped)", f);
  std::printf("\n");
  for (const Json& a : history) print_alarm(a, "t_s");
  return kExitOk;
}

}  // namespace edmhmi
