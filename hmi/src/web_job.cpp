#include "edm/hmi/web_job.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "edm/bridge/machine_info.hpp"
#include "edm/hmi/job_runner.hpp"

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
      default:
        break;
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
  have_tables_ = true;
  return true;
}

Json WebJob::machine_info() const {
  std::lock_guard lock(mutex_);
  if (!have_tables_) return nullptr;
  return bridge::to_json(tables_, machine_name_);
}

std::optional<Vec3> WebJob::position_locked() const {
  if (!last_status_) return std::nullopt;
  const JobFigures f = figures_from_status(*last_status_);
  return Vec3{f.x_mm.value_or(0.0), f.y_mm.value_or(0.0), f.z_mm.value_or(0.0)};
}

std::optional<GcodeResult> WebJob::interpret(const std::string& text, const std::string& name,
                                             GcodeOptions& options) const {
  machining::MachineTables tables;
  {
    std::lock_guard lock(mutex_);
    if (!have_tables_) return std::nullopt;
    tables = tables_;
    options.start_mm = position_locked().value_or(Vec3{});
  }
  return interpret_gcode(text, name, tables, options);
}

Json WebJob::check(const std::string& text, const std::string& name) {
  GcodeOptions options;
  const std::optional<GcodeResult> result = interpret(text, name, options);
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
  GcodeOptions options;
  std::optional<GcodeResult> result = interpret(text, name, options);
  if (!result) return no_machine_info();
  GcodeResult& g = *result;
  if (!g.ok()) {
    return {{"ok", false},
            {"code", "bad_program"},
            {"message", std::to_string(g.errors.size()) + " error(s) in the program"},
            {"errors", errors_json(g.errors)}};
  }
  const bridge::Reply up = client_.upload_program(g.blocks);
  if (!up) {
    Json errors = Json::array();
    if (up.details.is_object() && up.details.contains("issues") &&
        up.details["issues"].is_array()) {
      for (const Json& i : up.details["issues"]) {
        errors.push_back({{"line", i.value("line", 0)},
                          {"col", i.value("col", 0)},
                          {"message", i.value("message", std::string())}});
      }
    }
    return {{"ok", false},
            {"code", up.code ? std::string(bridge::to_string(*up.code)) : "transport"},
            {"message", "program refused: " + reply_error(up)},
            {"errors", errors}};
  }
  std::lock_guard lock(mutex_);
  part_ = name;
  text_ = text;
  generation_ = up.body.value("generation", std::uint64_t{0});
  toolpath_ = toolpath_points(g.blocks, options.start_mm, kMaxToolpathPoints);
  blocks_ = std::move(g.blocks);
  started_ = false;
  report_done_ = false;
  report_ = JobReport{};
  return {{"ok", true}, {"generation", generation_}, {"blocks", blocks_.size()}};
}

bridge::Reply WebJob::start() {
  std::optional<double> electrode;
  {
    std::lock_guard lock(mutex_);
    if (last_status_) electrode = figures_from_status(*last_status_).electrode_mm;
  }
  bridge::Reply r = client_.request("cycle.start");
  if (r) {
    std::lock_guard lock(mutex_);
    started_ = true;
    report_done_ = false;
    report_ = JobReport{};
    report_.part = part_;
    report_.machine = machine_name_;
    report_.targets = program_targets(blocks_);
    report_.electrode_at_start_mm = electrode;
  }
  return r;
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
          {"report", report}};
}

}  // namespace edm::hmi
