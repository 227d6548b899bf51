// The page's queue and electrode measurement (web_shift.hpp, docs/web.md "The shift").
#include "edm/hmi/web_shift.hpp"

#include <algorithm>
#include <cmath>

#include "edm/hmi/web_job.hpp"

namespace edm::hmi {
namespace {

using bridge::Json;

Json refused(std::string_view code, std::string message) {
  return {{"ok", false}, {"code", code}, {"message", std::move(message)}};
}

const char* outcome_name(RunOutcome o) {
  switch (o) {
    case RunOutcome::kFinished: return "finished";
    case RunOutcome::kAborted: return "aborted";
    case RunOutcome::kRefused: return "refused";
    case RunOutcome::kDetached: return "detached";
    case RunOutcome::kLost: return "lost";
    case RunOutcome::kInterrupted: return "interrupted";
  }
  return "?";
}

/// A session of the procedure's own, reconnecting by itself (a job outlives a lost link).
bool open_session(bridge::Client& client, const ConnectionSettings& settings, std::string& error) {
  try {
    bridge::ClientOptions o = client_options(settings);
    o.auto_reconnect = true;
    if (client.connect(o) != bridge::Role::kOperator) {
      error = "edmhmi serve's token is not an operator's";
      return false;
    }
    return true;
  } catch (const bridge::ClientError& e) {
    error = std::string("cannot reach edmplc: ") + e.what();
    return false;
  }
}

}  // namespace

WebShift::~WebShift() { stop_all(); }

void WebShift::stop_all() {
  queue_interrupt_ = true;
  measure_interrupt_ = true;
  if (queue_thread_.joinable()) queue_thread_.join();
  if (measure_thread_.joinable()) measure_thread_.join();
}

Json WebShift::add(const QueueItem& item) {
  std::lock_guard lock(mutex_);
  if (running_) return refused("busy", "the queue is running: stop it to change it");
  if (items_.size() >= kMaxItems) {
    return refused("bad_request",
                   "the queue holds at most " + std::to_string(kMaxItems) + " programs");
  }
  if (item.repeat < 1 || item.repeat > kMaxRepeat) {
    return refused("bad_request", "'repeat' must be 1 to " + std::to_string(kMaxRepeat));
  }
  if (!(std::abs(item.step_x_mm) <= kMaxStepMm) || !(std::abs(item.step_y_mm) <= kMaxStepMm)) {
    return refused("bad_request", "a step is at most 1000 mm");
  }
  items_.push_back(item);
  changed_locked();
  return {{"ok", true}, {"items", items_.size()}};
}

Json WebShift::control(std::string_view action) {
  std::unique_lock lock(mutex_);
  if (action == "stop") {
    if (!running_) return refused("bad_state", "the queue is not running");
    queue_interrupt_ = true;
    note_locked("stop asked: the job running is stopped and the queue ends");
    return {{"ok", true}};
  }
  if (running_) return refused("busy", "the queue is running");
  if (action == "clear") {
    items_.clear();
    changed_locked();
    return {{"ok", true}};
  }
  if (action != "start") return refused("bad_request", "unknown queue action");
  if (items_.empty()) return refused("bad_request", "the queue is empty: add a program first");
  running_ = true;
  waiting_change_ = false;
  ok_ = nullptr;
  message_.clear();
  jobs_.clear();
  notes_.clear();
  changed_locked();
  std::vector<QueueItem> items = items_;
  lock.unlock();
  if (queue_thread_.joinable()) queue_thread_.join();  // the last queue's, ended
  queue_interrupt_ = false;
  queue_thread_ = std::thread(
      [this, items = std::move(items)]() mutable { run_queue_thread(std::move(items)); });
  return {{"ok", true}};
}

Json WebShift::measure(const std::string& reference, const std::string& frame) {
  if (reference != "setter" && reference != "work") {
    return refused("bad_request", "'reference' is 'setter' or 'work'");
  }
  {
    std::lock_guard lock(mutex_);
    if (measuring_) return refused("busy", "a measurement is running");
    measuring_ = true;
    measure_ = {{"running", true}, {"reference", reference}, {"note", ""}};
    changed_locked();
  }
  if (measure_thread_.joinable()) measure_thread_.join();
  measure_interrupt_ = false;
  MeasureRequest req;
  req.reference = reference;
  req.frame = frame;
  measure_thread_ = std::thread([this, req] { run_measure_thread(req); });
  return {{"ok", true}};
}

void WebShift::run_measure_thread(MeasureRequest request) {
  bridge::Client client;
  std::string error;
  MeasureOutcome o;
  if (open_session(client, settings_, error)) {
    o = measure_electrode(client, request, measure_interrupt_, [this](const std::string& n) {
      std::lock_guard lock(mutex_);
      measure_["note"] = n;
      changed_locked();
    });
  } else {
    o.error = error;
  }
  std::lock_guard lock(mutex_);
  measuring_ = false;
  measure_["running"] = false;
  measure_["ok"] = o.ok();
  measure_["error"] = o.kind == MeasureOutcome::Kind::kInterrupted ? "interrupted" : o.error;
  if (o.ok()) {
    measure_["length_mm"] = o.length_mm;
    measure_["was_mm"] = o.was_mm;
  }
  changed_locked();
}

void WebShift::on_progress(const ProgressView& v) {
  std::lock_guard lock(mutex_);
  if (v.kind == machining::MotionKind::kDrill &&
      (current_.holes.empty() || current_.holes.back().line != v.line)) {
    current_.holes.push_back({v.line, v.drill_target_mm, -1.0});
  }
  if (!current_.holes.empty() && v.figures.hole_depth_mm) {
    Hole& h = current_.holes.back();  // the hole stays the deepest until the next one begins
    h.depth_mm = std::max(h.depth_mm, *v.figures.hole_depth_mm);
  }
  current_.time_s = v.elapsed_s;
  changed_locked();
}

void WebShift::run_queue_thread(std::vector<QueueItem> items) {
  bridge::Client client;
  std::string error;
  QueueResult r;
  if (open_session(client, settings_, error)) {
    QueueCallbacks cb;
    cb.run.progress = [this](const ProgressView& v) { on_progress(v); };
    cb.run.alarm = [this](const std::string& a) {
      std::lock_guard lock(mutex_);
      if (current_.alarms.size() < kMaxNotes) current_.alarms.push_back(a);
      changed_locked();
    };
    cb.run.note = [this](const std::string& n) {
      std::lock_guard lock(mutex_);
      note_locked(n);
    };
    cb.note = cb.run.note;
    cb.waiting = [this](bool w) {
      std::lock_guard lock(mutex_);
      waiting_change_ = w;
      changed_locked();
    };
    cb.job_start = [this](const QueueJob& j) {
      std::lock_guard lock(mutex_);
      current_ = Job{};
      current_.part = j.part;
      current_.run = j.run;
      current_.from_line = j.from_line;
      current_.before_line = j.before_line;
      changed_locked();
    };
    cb.job_done = [this](const QueueJob& j) {
      std::lock_guard lock(mutex_);
      Job done = std::move(current_);
      current_ = Job{};
      done.part = j.part;
      done.run = j.run;
      done.from_line = j.from_line;
      done.before_line = j.before_line;
      done.outcome = outcome_name(j.result.outcome);
      done.message = j.result.message;
      if (j.result.report.end.time_s) done.time_s = *j.result.report.end.time_s;
      jobs_.push_back(std::move(done));
      while (jobs_.size() > kMaxJobs) jobs_.pop_front();
      changed_locked();
    };
    try {
      r = run_queue(client, items, cb, queue_interrupt_);
    } catch (const std::exception& e) {  // a bridge failure between jobs
      r.ok = false;
      r.message = e.what();
    }
  } else {
    r.message = error;
  }
  std::lock_guard lock(mutex_);
  running_ = false;
  waiting_change_ = false;
  ok_ = r.ok;
  message_ = r.ok ? std::string("every job finished") : r.message;
  current_ = Job{};
  note_locked(message_);
}

void WebShift::note_locked(std::string text) {
  notes_.push_back(std::move(text));
  while (notes_.size() > kMaxNotes) notes_.pop_front();
  changed_locked();
}

Json WebShift::snapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_locked();
}

Json WebShift::take_changes() {
  std::lock_guard lock(mutex_);
  if (generation_ == sent_generation_) return nullptr;
  sent_generation_ = generation_;
  return snapshot_locked();
}

Json WebShift::snapshot_locked() const {
  Json items = Json::array();
  for (const QueueItem& i : items_) {
    items.push_back({{"name", i.part},
                     {"repeat", i.repeat},
                     {"step_x", i.step_x_mm},
                     {"step_y", i.step_y_mm},
                     {"bytes", i.text.size()}});
  }
  const auto job_json = [](const Job& j) {
    Json holes = Json::array();
    for (const Hole& h : j.holes) {
      holes.push_back({{"line", h.line},
                       {"target_mm", h.target_mm},
                       {"depth_mm", h.depth_mm < 0.0 ? Json() : Json(h.depth_mm)}});
    }
    return Json{{"part", j.part},           {"run", j.run},
                {"from_line", j.from_line}, {"before_line", j.before_line},
                {"outcome", j.outcome},     {"message", j.message},
                {"holes", holes},           {"time_s", j.time_s},
                {"alarms", j.alarms}};
  };
  Json jobs = Json::array();
  for (const Job& j : jobs_) jobs.push_back(job_json(j));
  return {{"items", items},
          {"running", running_},
          {"waiting_change", waiting_change_},
          {"ok", ok_},
          {"message", message_},
          {"current", current_.part.empty() ? Json() : job_json(current_)},
          {"jobs", jobs},
          {"notes", Json(notes_)},
          {"measure", measure_},
          {"generation", generation_}};
}

}  // namespace edm::hmi
