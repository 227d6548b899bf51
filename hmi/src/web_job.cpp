#include "edm/hmi/web_job.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "edm/bridge/machine_info.hpp"
#include "edm/hmi/job_runner.hpp"
#include "edm/hmi/mdi.hpp"
#include "edm/hmi/resume.hpp"

namespace edm::hmi {

namespace {

using bridge::Json;
using machining::MotionKind;
using machining::Vec3;

Json point(const Vec3& p) { return Json::array({p.x, p.y, p.z}); }

/// Chords of an XY circle arc from `from` about `c`, swept `sweep_rad` (sign = direction).
void add_arc(Json& out, const Vec3& from, const Vec3& c, double sweep_rad, double z_end) {
  const double r = std::hypot(from.x - c.x, from.y - c.y);
  const double a0 = std::atan2(from.y - c.y, from.x - c.x);
  const int n = std::clamp(
      static_cast<int>(std::ceil(std::abs(sweep_rad) / (std::numbers::pi / 18))), 1, 3600);
  for (int i = 1; i <= n; ++i) {
    const double f = static_cast<double>(i) / n;
    const double a = a0 + sweep_rad * f;
    out.push_back(
        Json::array({c.x + r * std::cos(a), c.y + r * std::sin(a), from.z + (z_end - from.z) * f}));
  }
}

Json no_machine_info() { return {{"ok", false}, {"message", "no machine.info yet"}}; }

std::string reply_error(const bridge::Reply& r) {
  return (r.code ? std::string(bridge::to_string(*r.code)) + ": " : std::string()) + r.message;
}

Json refused(std::string_view code, const std::string& message) {
  return {{"ok", false}, {"code", code}, {"message", message}};
}

Json refused(const bridge::Reply& r, const std::string& what) {
  return refused(r.code ? std::string(bridge::to_string(*r.code)) : "transport",
                 what + ": " + reply_error(r));
}

/// A refused upload, with the commit's issues located at their lines (program.commit's details).
Json commit_refused(const bridge::Reply& up) {
  Json errors = Json::array();
  if (up.details.is_object() && up.details.contains("issues") && up.details["issues"].is_array()) {
    for (const Json& i : up.details["issues"]) {
      errors.push_back({{"line", i.value("line", 0)},
                        {"col", i.value("col", 0)},
                        {"message", i.value("message", std::string())}});
    }
  }
  Json r = refused(up, "program refused");
  r["errors"] = std::move(errors);
  return r;
}

/// The frames of a program as runs: [first block, frame, ox, oy, oz] each time the frame (or the
/// G92 offset) changes — a few entries, whatever the program's length.
Json frame_runs(const std::vector<BlockFrame>& frames) {
  Json runs = Json::array();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i > 0 && frames[i] == frames[i - 1]) continue;
    const BlockFrame& f = frames[i];
    runs.push_back(Json::array({i, f.frame, f.offset_mm.x, f.offset_mm.y, f.offset_mm.z}));
  }
  return runs;
}

/// Each drilling block as [block index, source line, depth_mm]: what the page's depth bar and ETA
/// measure a running job against.
Json drill_list(const std::vector<machining::MotionBlock>& blocks) {
  Json out = Json::array();
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (blocks[i].kind == MotionKind::kDrill) {
      out.push_back(Json::array({i, blocks[i].line, blocks[i].depth_mm}));
    }
  }
  return out;
}

Json errors_json(const std::vector<GcodeError>& errors) {
  Json out = Json::array();
  for (const GcodeError& e : errors) {
    out.push_back({{"line", e.line}, {"col", e.col}, {"message", e.message}});
  }
  return out;
}

}  // namespace

Json toolpath_points(const std::vector<machining::MotionBlock>& blocks, const Vec3& start,
                     std::size_t max_points) {
  Json pts = Json::array();
  pts.push_back(point(start));
  Vec3 at = start;
  for (const machining::MotionBlock& b : blocks) {
    switch (b.kind) {
      case MotionKind::kRapid:
      case MotionKind::kLinear:
      case MotionKind::kDrill:
        pts.push_back(point(b.target));
        // A drilling block ends back where it started (DeepHoleDrill retracts).
        if (b.kind == MotionKind::kDrill) {
          pts.push_back(point(at));
        } else {
          at = b.target;
        }
        break;
      case MotionKind::kArcCw:
      case MotionKind::kArcCcw: {
        const double a0 = std::atan2(at.y - b.centre.y, at.x - b.centre.x);
        const double a1 = std::atan2(b.target.y - b.centre.y, b.target.x - b.centre.x);
        double sweep = a1 - a0;
        const bool cw = b.kind == MotionKind::kArcCw;
        if (cw && sweep >= 0) sweep -= 2 * std::numbers::pi;
        if (!cw && sweep <= 0) sweep += 2 * std::numbers::pi;
        sweep += (cw ? -1.0 : 1.0) * 2 * std::numbers::pi * std::max(0, b.turns);
        add_arc(pts, at, b.centre, sweep, b.target.z);
        at = b.target;
        break;
      }
      case MotionKind::kOrbitFinish: {
        const Vec3 c{at.x, at.y, at.z};
        pts.push_back(point({at.x + b.final_radius_mm, at.y, at.z}));
        add_arc(pts, {at.x + b.final_radius_mm, at.y, at.z}, c, 2 * std::numbers::pi, at.z);
        pts.push_back(point(at));
        break;
      }
      default: break;
    }
  }
  if (pts.size() <= max_points || max_points < 2) return pts;
  Json thin = Json::array();
  const double step = static_cast<double>(pts.size() - 1) / static_cast<double>(max_points - 1);
  for (std::size_t i = 0; i < max_points; ++i) {
    thin.push_back(pts[static_cast<std::size_t>(std::lround(static_cast<double>(i) * step))]);
  }
  return thin;
}

bool WebJob::refresh_machine(std::string& error) {
  const bridge::Reply info = client_.request("machine.info");
  if (!info) {
    error = "machine.info: " + reply_error(info);
    return false;
  }
  machining::MachineTables tables;
  std::string name;
  if (!bridge::from_json(info.body, tables, name, error)) return false;
  std::lock_guard lock(mutex_);
  tables_ = std::move(tables);
  machine_name_ = std::move(name);
  machine_raw_ = info.body;
  machine_raw_.erase("id");
  machine_raw_.erase("ok");
  have_tables_ = true;
  return true;
}

Json WebJob::machine_info_raw() const {
  std::lock_guard lock(mutex_);
  return machine_raw_;
}

bool WebJob::refresh_offsets(std::string& error) {
  const bridge::Reply r = client_.request("offset.get");
  if (!r) {
    if (r.code == bridge::ErrorCode::kUnknownOp) {  // an edmplc before issue 21: machine = work
      std::lock_guard lock(mutex_);
      offsets_ = WorkOffsets{};
      offsets_generation_.reset();
      offsets_json_ = nullptr;
      return true;
    }
    error = "offset.get: " + reply_error(r);
    return false;
  }
  WorkOffsets offsets;
  if (!offsets_from_json(r.body, offsets, error)) {
    error = "offset.get: " + error;
    return false;
  }
  const std::uint64_t generation = r.body.value("generation", std::uint64_t{0});
  std::lock_guard lock(mutex_);
  offsets_ = offsets;
  offsets_generation_ = generation;
  offsets_json_ = to_json(offsets);
  offsets_json_["generation"] = generation;
  return true;
}

Json WebJob::offsets_json() const {
  std::lock_guard lock(mutex_);
  return offsets_json_;
}

Json WebJob::machine_info() const {
  std::lock_guard lock(mutex_);
  if (!have_tables_) return nullptr;
  Json info = bridge::to_json(tables_, machine_name_);
  // The condition fields operators may edit (condition.set), as edmplc says; none from an older
  // one.
  info["condition_edit"] = machine_raw_.value("condition_edit", Json::array());
  return info;
}

std::optional<Vec3> WebJob::position_locked() const {
  if (!last_status_) return std::nullopt;
  const JobFigures f = figures_from_status(*last_status_);
  return Vec3{f.x_mm.value_or(0.0), f.y_mm.value_or(0.0), f.z_mm.value_or(0.0)};
}

std::optional<GcodeResult> WebJob::interpret(const std::string& text, const std::string& name,
                                             GcodeOptions& options,
                                             std::optional<std::uint64_t>& generation) const {
  machining::MachineTables tables;
  {
    std::lock_guard lock(mutex_);
    if (!have_tables_) return std::nullopt;
    tables = tables_;
    options.start_mm = position_locked().value_or(Vec3{});
    options.offsets = offsets_;
    generation = offsets_generation_;
  }
  return interpret_gcode(text, name, tables, options);
}

bridge::Reply WebJob::upload_blocks(const std::vector<machining::MotionBlock>& blocks,
                                    const std::string& slot,
                                    std::optional<std::uint64_t> generation) const {
  bridge::UploadOptions o;
  o.slot = slot;
  o.offsets_generation = generation;
  return client_.upload_program(blocks, o);
}

void WebJob::load_locked(std::string part, std::string text,
                         std::vector<machining::MotionBlock> blocks,
                         const std::vector<BlockFrame>& frames, const Vec3& start,
                         std::uint64_t generation) {
  part_ = std::move(part);
  text_ = std::move(text);
  generation_ = generation;
  toolpath_ = toolpath_points(blocks, start, kMaxToolpathPoints);
  drills_ = drill_list(blocks);
  blocks_ = std::move(blocks);
  frames_ = frames;
  frame_runs_ = frame_runs(frames_);
  resumed_from_.reset();
  started_ = false;
  dry_run_ = false;
  report_done_ = false;
  report_ = JobReport{};
}

Json WebJob::check(const std::string& text, const std::string& name) {
  std::string error;
  if (!refresh_offsets(error)) return refused("transport", error);
  GcodeOptions options;
  std::optional<std::uint64_t> generation;
  const std::optional<GcodeResult> result = interpret(text, name, options, generation);
  if (!result) return no_machine_info();
  const GcodeResult& g = *result;
  return {{"ok", g.ok()},
          {"errors", errors_json(g.errors)},
          {"blocks", g.blocks.size()},
          {"drill_blocks", g.drill_blocks},
          {"drill_depth_mm", g.drill_depth_mm},
          {"electrode_wear_mm", g.electrode_wear_mm}};
}

Json WebJob::upload(const std::string& text, const std::string& name) {
  std::string error;
  if (!refresh_offsets(error)) return refused("transport", error);
  GcodeOptions options;
  std::optional<std::uint64_t> offsets_generation;
  std::optional<GcodeResult> result = interpret(text, name, options, offsets_generation);
  if (!result) return no_machine_info();
  GcodeResult& g = *result;
  if (!g.ok()) {
    return {{"ok", false},
            {"code", "bad_program"},
            {"message", std::to_string(g.errors.size()) + " error(s) in the program"},
            {"errors", errors_json(g.errors)}};
  }
  const bridge::Reply up = upload_blocks(g.blocks, "", offsets_generation);
  if (!up) return commit_refused(up);
  std::lock_guard lock(mutex_);
  load_locked(name, text, std::move(g.blocks), g.frames, options.start_mm,
              up.body.value("generation", std::uint64_t{0}));
  return {{"ok", true}, {"generation", generation_}, {"blocks", blocks_.size()}};
}

bridge::Reply WebJob::start(bool dry_run) {
  std::optional<double> electrode;
  {
    std::lock_guard lock(mutex_);
    if (last_status_) electrode = figures_from_status(*last_status_).electrode_mm;
  }
  // Only a dry run says so: an edmplc before issue 21 knows no "dry_run".
  bridge::Reply r =
      client_.request("cycle.start", dry_run ? Json{{"dry_run", true}} : Json::object());
  if (r) {
    std::lock_guard lock(mutex_);
    started_ = true;
    dry_run_ = dry_run;
    report_done_ = false;
    report_ = JobReport{};
    report_.dry_run = dry_run;  // nothing drilled: the report gives no depth error
    report_.part = part_;
    report_.machine = machine_name_;
    report_.targets = frames_.size() == blocks_.size() ? program_targets(blocks_, frames_)
                                                       : program_targets(blocks_);
    report_.electrode_at_start_mm = electrode;
  }
  return r;
}

Json WebJob::start_from(std::int32_t line, std::optional<double> depth_done_mm, bool dry_run) {
  std::string error;
  if (!refresh_offsets(error)) return refused("transport", error);
  std::string part, text;
  std::optional<bridge::LastJob> last;
  {
    std::lock_guard lock(mutex_);
    part = part_;
    text = text_;
    if (last_status_) last = last_status_->job_last;
  }
  if (text.empty()) return refused("invalid_state", "no program loaded: upload one first");
  GcodeOptions options;
  std::optional<std::uint64_t> offsets_generation;
  const std::optional<GcodeResult> g = interpret(text, part, options, offsets_generation);
  if (!g) return no_machine_info();
  if (!g->ok()) {
    Json r = refused("bad_program", std::to_string(g->errors.size()) + " error(s) in the program");
    r["errors"] = errors_json(g->errors);
    return r;
  }
  machining::MachineTables tables;
  {
    std::lock_guard lock(mutex_);
    tables = tables_;
  }
  // The depth the hole on that line already has: the operator's figure, else the runtime's record
  // of the last job when it ended on that very line (as `edmhmi run --from`), else none.
  ResumePlan plan = plan_resume(*g, tables, line, 0.0);
  std::string depth_from = "none";
  if (plan.ok() && plan.drill) {
    double depth = 0.0;
    std::optional<DrillResume> state;  // the interrupted drill's touch Z and wear: it counts on
    if (depth_done_mm) {
      depth = *depth_done_mm;
      depth_from = "operator";
    } else if (last && last->line == plan.line && last->depth_mm) {
      depth = std::max(0.0, *last->depth_mm);
      depth_from = "last job (" + last->outcome + ")";
      if (last->touch_z_mm && last->wear_mm) {
        state = DrillResume{*last->touch_z_mm, *last->wear_mm};
        depth_from += ", its touch Z and wear";
      }
    }
    if (depth > 0.0) plan = plan_resume(*g, tables, line, depth, state);
  } else if (plan.ok() && depth_done_mm && *depth_done_mm > 0.0) {
    plan = plan_resume(*g, tables, line, *depth_done_mm);  // refused: no drilling on that line
  }
  if (!plan.ok())
    return refused("bad_request", "from line " + std::to_string(line) + ": " + plan.error);
  const bridge::Reply up = upload_blocks(plan.blocks, "", offsets_generation);
  if (!up) return commit_refused(up);
  {
    std::lock_guard lock(mutex_);
    load_locked(part, text, plan.blocks, plan.frames, options.start_mm,
                up.body.value("generation", std::uint64_t{0}));
    resumed_from_ = plan.line;
  }
  const bridge::Reply r = start(dry_run);
  if (!r) return refused(r, "resumed program committed; cycle.start");
  return {{"ok", true},
          {"line", plan.line},
          {"first_block", plan.first + 1},
          {"prologue", plan.prologue},
          {"blocks", plan.blocks.size()},
          {"depth_done_mm", plan.depth_done_mm},
          {"depth_from", depth_from},
          {"clearance_z_mm", plan.clearance_z_mm}};
}

Json WebJob::mdi(const std::string& line) {
  std::string error;
  if (!refresh_offsets(error)) return refused("transport", error);
  machining::MachineTables tables;
  WorkOffsets offsets;
  std::optional<std::uint64_t> generation;
  Vec3 position;
  {
    std::lock_guard lock(mutex_);
    if (!have_tables_) return no_machine_info();
    tables = tables_;
    offsets = offsets_;
    generation = offsets_generation_;
    position = position_locked().value_or(Vec3{});
  }
  const GcodeResult g = interpret_mdi(line, tables, offsets, position);
  if (!g.ok()) {
    Json r = refused("bad_program", g.messages().empty() ? "bad line" : g.messages().front());
    r["errors"] = errors_json(g.errors);
    return r;
  }
  const bridge::Reply up = upload_blocks(g.blocks, "mdi", generation);
  if (!up) return refused(up, "MDI refused");
  const bridge::Reply r = client_.request("cycle.start", Json{{"slot", "mdi"}});
  if (!r) return refused(r, "MDI committed; cycle.start");
  return {{"ok", true}, {"blocks", g.blocks.size()}};
}

void WebJob::on_status(const bridge::StatusMessage& s) {
  std::lock_guard lock(mutex_);
  last_status_ = s;
  if (!started_ || report_done_ || s.job_generation != generation_) return;
  if (s.job_outcome == "finished" || s.job_outcome == "aborted") {
    fill_from_status(report_, s);
    report_done_ = true;
    report_done_at_ = std::chrono::steady_clock::now();
  }
}

void WebJob::on_alarm(const Json& ev) {
  std::lock_guard lock(mutex_);
  constexpr auto kLateAlarm = std::chrono::seconds(2);
  if (!started_) return;
  if (report_done_ && std::chrono::steady_clock::now() - report_done_at_ > kLateAlarm) return;
  report_.alarms.push_back(describe_alarm(ev));
  report_.fault_alarms += ev.value("severity", std::string()) == "fault" ? 1 : 0;
}

Json WebJob::snapshot() const {
  std::lock_guard lock(mutex_);
  Json report = nullptr;
  if (report_done_) {
    report = {{"text", format_report(report_)},
              {"outcome", report_.outcome},
              {"blocks_done", report_.blocks_done},
              {"alarms", report_.alarms}};
  }
  return {{"part", part_},
          {"text", text_},
          {"generation", generation_},
          {"blocks", blocks_.size()},
          {"started", started_},
          {"toolpath", toolpath_},
          {"frames", frame_runs_},
          {"resumed_from", resumed_from_ ? Json(*resumed_from_) : Json(nullptr)},
          {"drills", drills_},
          {"dry_run", dry_run_},
          {"report", report}};
}

}  // namespace edm::hmi
