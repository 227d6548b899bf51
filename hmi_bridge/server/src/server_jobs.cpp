// The bridge's job log (job_log.hpp; docs/protocol.md "jobs.get"): a job's start and end are
// seen on the progress tick (100 ms); an ended job is logged one tick later, so the alarms that
// ended it (drained and posted by the runtime's alarm thread) are in its entry.
#include <chrono>
#include <cstdio>

#include "edm/bridge/codec.hpp"
#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge {
namespace {

std::string wall_now() { return ops::wall_time(std::chrono::system_clock::now()); }

}  // namespace

void Server::Impl::watch_jobs(const rt::JobProgress& p) {
  JobWatch& w = job_watch;
  auto take_recent = [&w] {
    if (w.recent.empty() || w.entry.alarms.size() >= 4000) return;
    w.entry.alarms += (w.entry.alarms.empty() ? "" : "; ") + w.recent;
  };
  bool taken = false;
  if (w.active) {  // the alarms since the last tick are the running (or just ended) job's
    take_recent();
    taken = true;
  }
  if (w.settle_ticks > 0 && --w.settle_ticks == 0) log_job();
  if (p.jobs_started != w.started) {
    if (w.active) log_job();  // it ended and another began within one tick
    w.started = p.jobs_started;
    w.active = true;
    w.settle_ticks = -1;
    w.entry = JobLogEntry{};
    w.entry.start = wall_now();
    w.entry.electrode_start_mm = rt.electrode().length_mm();
    // The electrode used is the one in the spindle at the start (a change waits for READY).
    if (const ElectrodeEntry* used = electrodes->current()) w.entry.electrode = used->id;
    if (!taken) take_recent();  // it began within the last tick: so did its alarms
  }
  w.recent.clear();
  note_job_end(p);
}

void Server::Impl::note_job_end(const rt::JobProgress& p) {
  JobWatch& w = job_watch;
  // Ended: not running and not active. (Progress fields are read one by one: just after a start
  // the count may be new and the outcome still the last job's; the job is active then.)
  if (w.active && w.settle_ticks < 0 && p.outcome != rt::JobOutcome::kRunning &&
      !rt.job().active()) {
    w.end = p;
    w.entry.end = wall_now();
    w.settle_ticks = 1;
    take_figures();  // now: the next job resets them as it begins
  }
}

void Server::Impl::take_figures() {
  JobWatch& w = job_watch;
  if (job_block.empty()) return;
  // From the process image now (the status snapshot may be a period old).
  const auto read = [&](const char* figure) {
    return rt.variables().read(job_block + figure).value_or(0.0);
  };
  w.entry.time_s = read(".job_time_s");
  w.entry.depth_mm = read(".job_depth_mm");
  w.entry.wear_mm = read(".job_wear_mm");
  w.entry.holes = static_cast<std::int64_t>(read(".job_holes"));
  w.drilled_mm = read(".job_drilled_mm");
}

void Server::Impl::log_job() {
  JobWatch& w = job_watch;
  JobLogEntry& e = w.entry;
  const rt::JobProgress& p = w.end;
  if (e.end.empty()) e.end = wall_now();
  e.outcome = std::string(rt::outcome_name(p.outcome));
  e.slot = p.slot == rt::JobSlot::kMdi ? "mdi" : "main";
  e.dry_run = p.dry_run;
  char crc[16];
  std::snprintf(crc, sizeof crc, "0x%08x", p.program_id);
  e.program = crc;
  e.blocks_done = p.block_index;
  e.blocks = p.block_count;
  e.line = p.line;
  e.electrode_end_mm = rt.electrode().length_mm();
  const rt::MachineState st = rt.machine().state();
  e.cause = st == rt::MachineState::kFault || st == rt::MachineState::kEstop
                ? static_cast<int>(rt.machine().last_cause())
                : 0;
  if (!e.dry_run && !e.electrode.empty()) {
    electrodes->add_job(e.electrode, e.holes, w.drilled_mm, e.electrode_end_mm);
    electrodes->save();
  }
  job_log->add(std::move(e));
  w.active = false;
  w.settle_ticks = -1;
  w.entry = JobLogEntry{};
}

namespace ops {

Body op_jobs_get(Session& s, const Json& msg) {
  auto& srv = s.server();
  std::size_t limit = 100;
  if (auto it = msg.find("limit"); it != msg.end()) {
    if (!it->is_number_integer() || it->get<std::int64_t>() < 1 ||
        it->get<std::int64_t>() > static_cast<std::int64_t>(Server::Impl::kJobLogCap)) {
      return error(ErrorCode::kBadRequest, "'limit' must be a whole number in 1 .. 1000");
    }
    limit = it->get<std::size_t>();
  }
  bool csv = false;
  if (auto it = msg.find("csv"); it != msg.end()) {
    if (!it->is_boolean()) return error(ErrorCode::kBadRequest, "'csv' must be true or false");
    csv = it->get<bool>();
  }
  const auto& all = srv.job_log->entries();
  Json jobs = Json::array();
  for (std::size_t i = all.size() > limit ? all.size() - limit : 0; i < all.size(); ++i) {
    const JobLogEntry& e = all[i];
    jobs.push_back({{"n", e.n},
                    {"start", e.start},
                    {"end", e.end},
                    {"outcome", e.outcome},
                    {"slot", e.slot},
                    {"dry_run", e.dry_run},
                    {"program", e.program},
                    {"blocks_done", e.blocks_done},
                    {"blocks", e.blocks},
                    {"line", e.line},
                    {"time_s", e.time_s},
                    {"depth_mm", e.depth_mm},
                    {"wear_mm", e.wear_mm},
                    {"electrode_start_mm", e.electrode_start_mm},
                    {"electrode_end_mm", e.electrode_end_mm},
                    {"cause", e.cause},
                    {"alarms", e.alarms},
                    {"electrode", e.electrode},
                    {"holes", e.holes}});
  }
  Json out = {
      {"jobs", std::move(jobs)}, {"total", all.size()}, {"retained", srv.job_log->retained()}};
  if (csv) out["csv"] = srv.job_log->csv();
  return out;
}

}  // namespace ops
}  // namespace edm::bridge
