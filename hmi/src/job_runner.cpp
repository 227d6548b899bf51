#include "edm/hmi/job_runner.hpp"

#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>

#include "edm/bridge/machine_info.hpp"

namespace edm::hmi {

namespace {

using bridge::Json;
using bridge::StatusMessage;
using Clock = std::chrono::steady_clock;

bool is_safe_state(const std::string& state) { return state == "FAULT" || state == "ESTOP"; }

/// Runtime seconds after which a status snapshot surely postdates a cycle.start (many cycles).
constexpr double kMdiSettleS = 0.1;

/// Events arrive on the client's I/O thread; the runner reads them on its own.
struct Inbox {
  std::mutex mutex;
  std::condition_variable cv;
  std::optional<StatusMessage> status;  // the latest
  std::uint64_t status_count{0};
  std::deque<std::pair<std::string, bool>> alarms;  // text, fault severity
  bool connection_changed{false};
};

/// Depth rate over the last few seconds of drilling, for the ETA of the current hole.
class DepthRate {
 public:
  void add(double t_s, double depth_mm) {
    samples_.emplace_back(t_s, depth_mm);
    while (samples_.size() > 2 && samples_.back().first - samples_.front().first > kWindowS) {
      samples_.pop_front();
    }
  }
  void clear() { samples_.clear(); }
  [[nodiscard]] std::optional<double> mm_per_s() const {
    if (samples_.size() < 2) return std::nullopt;
    const double dt = samples_.back().first - samples_.front().first;
    const double dd = samples_.back().second - samples_.front().second;
    if (dt < 1.0 || dd <= 0.0) return std::nullopt;
    return dd / dt;
  }

 private:
  static constexpr double kWindowS = 10.0;
  std::deque<std::pair<double, double>> samples_;
};

std::vector<std::string> commit_issues(const bridge::Reply& r, const std::string& part) {
  std::vector<std::string> out;
  if (!r.details.is_object()) return out;
  const auto it = r.details.find("issues");
  if (it == r.details.end() || !it->is_array()) return out;
  for (const Json& i : *it) {
    out.push_back(part + ":" + std::to_string(i.value("line", 0)) + ":" +
                  std::to_string(i.value("col", 0)) + ": " + i.value("message", std::string()));
  }
  return out;
}

RunResult refused(std::string message) {
  RunResult r;
  r.outcome = RunOutcome::kRefused;
  r.message = std::move(message);
  return r;
}

std::string reply_error(const bridge::Reply& r) {
  return (r.code ? std::string(bridge::to_string(*r.code)) + ": " : std::string()) + r.message;
}

}  // namespace

std::string describe_alarm(const Json& e) {
  return std::to_string(e.value("code", 0)) + " " + e.value("name", std::string("?")) + " (" +
         e.value("severity", std::string("?")) + ", " + e.value("source", std::string("?")) +
         "): " + e.value("text", std::string());
}

WorkOffsets fetch_offsets(bridge::Client& client, std::uint64_t* generation) {
  const bridge::Reply r = client.request("offset.get");
  if (!r) throw bridge::ClientError("offset.get: " + reply_error(r), r.code);
  WorkOffsets o;
  std::string error;
  if (!offsets_from_json(r.body, o, error)) {
    throw bridge::ClientError("offset.get: malformed reply: " + error);
  }
  if (generation != nullptr) *generation = r.body.value("generation", std::uint64_t{0});
  return o;
}

MachineView fetch_machine(bridge::Client& client) {
  MachineView m;
  const bridge::Reply info = client.request("machine.info");
  if (!info) throw bridge::ClientError("machine.info: " + reply_error(info), info.code);
  std::string error;
  if (!bridge::from_json(info.body, m.tables, m.name, error)) {
    throw bridge::ClientError("machine.info: malformed reply: " + error);
  }
  if (const auto manual = info.body.find("manual");
      manual != info.body.end() && manual->is_object()) {
    if (const auto d = manual->find("deadman_ms"); d != manual->end() && d->is_number()) {
      const double v = d->get<double>();
      if (std::isfinite(v) && v > 0.0) m.deadman_ms = v;
    }
  }
  const bridge::Reply st = client.request("status");
  if (!st || !bridge::from_json(st.body, m.status, error)) {
    throw bridge::ClientError("status: " + (st ? "malformed reply: " + error : reply_error(st)),
                              st.code);
  }
  m.last_job = m.status.job_last;
  const JobFigures f = figures_from_status(m.status);
  m.position = {f.x_mm.value_or(0.0), f.y_mm.value_or(0.0), f.z_mm.value_or(0.0)};
  try {
    std::uint64_t generation = 0;
    m.offsets = fetch_offsets(client, &generation);
    m.offsets_generation = generation;
  } catch (const bridge::ClientError& e) {
    if (e.code() != bridge::ErrorCode::kUnknownOp) throw;  // an edmplc without work offsets
  }
  return m;
}

RunResult run_job(bridge::Client& client, const RunRequest& req, const RunCallbacks& cb,
                  const std::atomic<bool>& interrupt) {
  std::string error;
  StatusMessage before;
  {
    const bridge::Reply st = client.request("status");
    if (!st || !bridge::from_json(st.body, before, error)) {
      return refused("status: " + (st ? error : reply_error(st)));
    }
  }
  if (before.state == "RUNNING" || before.state == "HOLD" || before.job_outcome == "running") {
    return refused("the machine is " + before.state + " with a job at block " +
                   std::to_string(before.job_block + 1) + "/" + std::to_string(before.job_blocks) +
                   "; stop it first (edmhmi stop)");
  }
  if (is_safe_state(before.state)) {
    return refused("the machine is in " + before.state + " (alarm " + std::to_string(before.cause) +
                   "); clear the cause, then edmhmi reset");
  }

  bridge::UploadOptions upload;
  upload.slot = req.slot;
  upload.offsets_generation = req.offsets_generation;
  const bridge::Reply up = client.upload_program(req.blocks, upload);
  if (!up) {
    RunResult r = refused("program refused: " + reply_error(up));
    r.locations = commit_issues(up, req.part);
    r.bad_program = up.code == bridge::ErrorCode::kBadRequest;
    return r;
  }
  const auto generation = up.body.value("generation", std::uint64_t{0});

  Inbox inbox;
  // An alarm raised before this job (e.g. 182 at power-on, acknowledged by a reset) may reach a
  // fresh subscriber late (the runtime broadcasts in batches): only those of the job's own time
  // belong to its report.
  const double since_s = before.t_s;
  client.set_event_handler([&inbox, since_s](const Json& ev) {
    const std::string kind = ev.value("event", std::string());
    std::lock_guard lock(inbox.mutex);
    if (kind == "status") {
      StatusMessage s;
      std::string e;
      if (bridge::from_json(ev, s, e)) {
        inbox.status = std::move(s);
        ++inbox.status_count;
      }
    } else if (kind == "alarm") {
      if (ev.value("t_s", since_s) < since_s) return;  // older than the job
      inbox.alarms.emplace_back(describe_alarm(ev), ev.value("severity", std::string()) == "fault");
    } else {
      return;  // progress and trace events: the status carries what the runner needs
    }
    inbox.cv.notify_one();
  });
  client.set_connection_handler([&inbox](bool) {
    std::lock_guard lock(inbox.mutex);
    inbox.connection_changed = true;
    inbox.cv.notify_one();
  });
  struct Detach {  // the handlers reference this frame: clear them on every way out
    bridge::Client& c;
    ~Detach() {
      c.set_event_handler(nullptr);
      c.set_connection_handler(nullptr);
    }
  } detach_guard{client};

  if (const bridge::Reply s = client.subscribe({"status", "alarm", "progress"}, req.rate_hz); !s) {
    return refused("subscribe: " + reply_error(s));
  }
  Json start = Json::object();
  if (!req.slot.empty()) start["slot"] = req.slot;
  if (req.dry_run) start["dry_run"] = true;
  if (const bridge::Reply s = client.request("cycle.start", start); !s) {
    return refused("cycle.start: " + reply_error(s));
  }
  // Snapshots taken before the start (the reply comes after them on the connection) show the
  // previous job: skip them.
  std::uint64_t seen = 0;
  {
    std::lock_guard lock(inbox.mutex);
    seen = inbox.status_count;
  }
  // The MDI slot's load does not change job.generation (that counts main programs): an MDI job's
  // end is the machine leaving RUNNING after it was seen running — or, for a job too short to be
  // seen, a snapshot taken well after the start (a status event may carry a snapshot a cycle
  // older than the start, with the previous job's outcome).
  const bool mdi = req.slot == "mdi";
  double mdi_after_t_s = 0.0;
  if (mdi) {
    StatusMessage now;
    const bridge::Reply st = client.request("status");
    if (st && bridge::from_json(st.body, now, error)) mdi_after_t_s = now.t_s + kMdiSettleS;
  }
  bool seen_running = false;

  RunResult result;
  result.report.part = req.part;
  result.report.machine = req.machine;
  result.report.targets = program_targets(req.blocks, req.frames);
  result.report.dry_run = req.dry_run;
  result.report.electrode_at_start_mm = figures_from_status(before).electrode_mm;
  if (req.detach) {
    result.outcome = RunOutcome::kDetached;
    return result;
  }

  const Clock::time_point t0 = Clock::now();
  bool offline = false;  // (not an optional: GCC 12 -Wmaybe-uninitialized false positive)
  Clock::time_point offline_since{};
  bool stop_sent = false;
  Clock::time_point stop_sent_at{};
  DepthRate rate;
  StatusMessage last = before;
  for (;;) {
    std::optional<StatusMessage> st;
    std::vector<std::pair<std::string, bool>> alarms;
    {
      std::unique_lock lock(inbox.mutex);
      inbox.cv.wait_for(lock, std::chrono::milliseconds(200), [&] {
        return inbox.status_count != seen || !inbox.alarms.empty() || inbox.connection_changed;
      });
      if (inbox.status_count != seen) {
        seen = inbox.status_count;
        st = inbox.status;
      }
      alarms.assign(inbox.alarms.begin(), inbox.alarms.end());
      inbox.alarms.clear();
      inbox.connection_changed = false;
    }
    for (const auto& [text, fault] : alarms) {
      result.report.alarms.push_back(text);
      result.report.fault_alarms += fault ? 1 : 0;
      if (cb.alarm) cb.alarm(text);
    }
    if (!client.connected()) {
      if (!offline) {
        offline = true;
        offline_since = Clock::now();
        if (cb.note) cb.note("connection to edmplc lost; the job runs on; reconnecting...");
      } else if (Clock::now() - offline_since > req.lost_limit) {
        result.outcome = RunOutcome::kLost;
        result.message = "edmplc unreachable for " +
                         std::to_string(std::chrono::duration_cast<std::chrono::seconds>(
                                            Clock::now() - offline_since)
                                            .count()) +
                         " s; the job may still run (edmhmi status)";
        return result;
      }
    } else if (offline) {
      offline = false;
      if (cb.note) cb.note("reconnected");
    }
    if (interrupt.load() && !client.connected()) {
      // Interrupted and cut off (e.g. the whole process group got the Ctrl-C, edmplc too): the
      // operator wants out; there is nobody to send the stop to.
      result.outcome = RunOutcome::kInterrupted;
      result.message = "interrupted while disconnected from edmplc; the job's state is unknown";
      return result;
    }
    if (interrupt.load() && stop_sent && Clock::now() - stop_sent_at > std::chrono::seconds(10)) {
      result.outcome = RunOutcome::kInterrupted;
      result.message = "interrupted; the machine did not confirm the stop within 10 s";
      return result;
    }
    if (interrupt.load() && !stop_sent && client.connected()) {
      stop_sent_at = Clock::now();
      stop_sent = true;
      const bridge::Reply r = client.request("cycle.stop");
      if (cb.note) {
        cb.note(r ? "interrupted: cycle.stop sent" : "interrupted: cycle.stop: " + reply_error(r));
      }
    }
    if (!st) continue;
    last = *st;
    if (!mdi && last.job_generation != generation) continue;  // not our program (yet)

    ProgressView v;
    v.state = last.state;
    v.outcome = last.job_outcome;
    v.block = last.job_block;
    v.blocks = last.job_blocks;
    v.line = last.job_line;
    v.figures = figures_from_status(last);
    if (last.job_block < req.blocks.size()) {
      const machining::MotionBlock& b = req.blocks[last.job_block];
      v.kind = b.kind;
      if (b.kind == machining::MotionKind::kDrill) v.drill_target_mm = drill_depth_of(b);
    }
    v.elapsed_s =
        v.figures.time_s.value_or(std::chrono::duration<double>(Clock::now() - t0).count());
    if (v.drill_target_mm > 0.0 && v.figures.depth_mm) {
      rate.add(v.elapsed_s, *v.figures.depth_mm);
      if (const auto mmps = rate.mm_per_s()) {
        v.eta_s = std::max(0.0, v.drill_target_mm - *v.figures.depth_mm) / *mmps;
      }
    } else {
      rate.clear();
      if (v.block > 0 && v.blocks > v.block) {
        v.eta_s =
            v.elapsed_s * static_cast<double>(v.blocks - v.block) / static_cast<double>(v.block);
      }
    }
    if (cb.progress) cb.progress(v);
    const bool running = last.state == "RUNNING" || last.state == "HOLD";
    if (running || last.job_outcome == "running") seen_running = true;
    const bool ended = last.job_outcome == "finished" || last.job_outcome == "aborted";
    if (ended && (!mdi || (!running && (seen_running || last.t_s > mdi_after_t_s)))) break;
  }

  // The final figures: one more status, so the report shows the job's last cycle.
  StatusMessage final_status = last;
  if (const bridge::Reply st = client.request("status"); st) {
    StatusMessage s;
    if (bridge::from_json(st.body, s, error) && (mdi || s.job_generation == generation)) {
      final_status = s;
    }
  }
  {  // alarms that came with the end
    std::lock_guard lock(inbox.mutex);
    for (const auto& [text, fault] : inbox.alarms) {
      result.report.alarms.push_back(text);
      result.report.fault_alarms += fault ? 1 : 0;
      if (cb.alarm) cb.alarm(text);
    }
    inbox.alarms.clear();
  }
  fill_from_status(result.report, final_status);
  if (final_status.job_outcome == "finished") {
    result.outcome = RunOutcome::kFinished;
  } else {
    result.outcome = stop_sent ? RunOutcome::kInterrupted : RunOutcome::kAborted;
  }
  return result;
}

}  // namespace edm::hmi
