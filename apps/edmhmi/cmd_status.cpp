// edmhmi status | stats — what the machine and its tasks are doing (docs/hmi.md).
#include <cmath>
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/job_report.hpp"

namespace edmhmi {

int cmd_status(const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const edm::bridge::Reply r = client.request("status");
  if (!r) return report_error("status", r);
  edm::bridge::StatusMessage s;
  std::string error;
  if (!edm::bridge::from_json(r.body, s, error)) {
    std::fprintf(stderr, "edmhmi: status: malformed reply: %s\n", error.c_str());
    return kExitFailure;
  }
  std::string machine;
  if (const edm::bridge::Reply info = client.request("machine.info"); info) {
    machine = info.body.value("name", std::string());
  }
  std::printf("edmplc %s:%u  machine %s  state %s", settings.host.c_str(), unsigned{settings.port},
              machine.empty() ? "?" : machine.c_str(), s.state.c_str());
  if (s.cause != 0) std::printf(" (alarm %d)", s.cause);
  std::printf("  t %.3f s  cycle %llu\n", s.t_s, static_cast<unsigned long long>(s.cycle));
  if (s.job_generation == 0) {
    std::printf("job: no program loaded\n");
  } else {
    std::printf("job: %s, program #%llu, block %llu of %llu (line %d)\n", s.job_outcome.c_str(),
                static_cast<unsigned long long>(s.job_generation),
                static_cast<unsigned long long>(std::min(s.job_block + 1, s.job_blocks)),
                static_cast<unsigned long long>(s.job_blocks), s.job_line);
    if (s.job_outcome == "finished" || s.job_outcome == "aborted" || s.job_outcome == "running") {
      edm::hmi::JobReport rep;
      rep.part = "program #" + std::to_string(s.job_generation);
      rep.machine = machine;
      rep.targets.blocks = s.job_blocks;
      rep.alarms_seen = false;  // the status has the last cause, not the job's alarms
      edm::hmi::fill_from_status(rep, s);
      std::fputs(edm::hmi::format_report(rep).c_str(), stdout);
    }
  }
  if (!print_active_alarms(client)) return kExitFailure;
  std::printf("variables:\n");
  for (const auto& [name, value] : s.vars) {
    std::printf("  %-28s %.6g\n", name.c_str(), value);
  }
  return kExitOk;
}

int cmd_stats(const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const edm::bridge::Reply r = client.request("tasks.stats");
  if (!r) return report_error("tasks.stats", r);
  std::printf("%-12s %9s %4s %12s %9s %8s %9s %9s %9s %9s %9s\n", "task", "interval", "prio",
              "cycles", "overruns", "omitted", "exec p50", "exec p99", "exec max", "lat p99",
              "lat max");
  for (const auto& t : r.body.value("tasks", edm::bridge::Json::array())) {
    const auto& e = t.value("exec_us", edm::bridge::Json::object());
    const auto& l = t.value("latency_us", edm::bridge::Json::object());
    std::printf("%-12s %7.0fus %4d %12llu %9llu %8llu %7.1fus %7.1fus %7.1fus %7.1fus %7.1fus\n",
                t.value("name", std::string("?")).c_str(), t.value("interval_us", 0.0),
                t.value("priority", 0), t.value("cycles", 0ULL), t.value("overruns", 0ULL),
                t.value("omitted_cycles", 0ULL), e.value("p50", 0.0), e.value("p99", 0.0),
                e.value("max", 0.0), l.value("p99", 0.0), l.value("max", 0.0));
  }
  if (const auto b = r.body.find("bridge"); b != r.body.end() && b->is_object()) {
    std::printf("bridge:");
    for (const auto& [k, v] : b->items()) std::printf(" %s %s", k.c_str(), v.dump().c_str());
    std::printf("\n");
  }
  return kExitOk;
}

}  // namespace edmhmi
