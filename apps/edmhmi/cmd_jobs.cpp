// edmhmi jobs [--csv] [--limit N] — the job log: each job that ended, with its outcome, figures,
// electrode and alarms (jobs.get, docs/hmi.md "The job log"); --csv prints the log as CSV.
#include <cstdio>
#include <string>

#include "cli.hpp"

namespace edmhmi {

int cmd_jobs(bool csv, int limit, const edm::hmi::ConnectionSettings& settings) {
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  edm::bridge::Json params = {{"limit", limit}};
  if (csv) params["csv"] = true;
  const edm::bridge::Reply r = client.request("jobs.get", params);
  if (!r) return report_error("jobs.get", r);
  if (csv) {
    std::fputs(r.body.value("csv", std::string()).c_str(), stdout);
    return kExitOk;
  }
  const edm::bridge::Json jobs = r.body.value("jobs", edm::bridge::Json::array());
  std::printf("%zu of %zu job(s)%s\n", jobs.size(), r.body.value("total", std::size_t{0}),
              r.body.value("retained", false) ? "" : " (not retained: no retain file)");
  std::printf("%5s  %-24s %-9s %-4s %-10s %8s %9s %8s %9s  %s\n", "n", "end (UTC)", "outcome",
              "slot", "program", "time s", "depth mm", "wear mm", "electrode", "alarms");
  for (const edm::bridge::Json& j : jobs) {
    std::string outcome = j.value("outcome", std::string("?"));
    if (j.value("dry_run", false)) outcome += "*";
    std::printf("%5llu  %-24s %-9s %-4s %-10s %8.1f %9.4f %8.3f %9.3f  %s\n",
                static_cast<unsigned long long>(j.value("n", 0ULL)),
                j.value("end", std::string()).c_str(), outcome.c_str(),
                j.value("slot", std::string()).c_str(), j.value("program", std::string()).c_str(),
                j.value("time_s", 0.0), j.value("depth_mm", 0.0), j.value("wear_mm", 0.0),
                j.value("electrode_end_mm", 0.0), j.value("alarms", std::string()).c_str());
  }
  if (!jobs.empty()) std::printf("(* a dry run; electrode: the length estimate at the end)\n");
  return kExitOk;
}

}  // namespace edmhmi
