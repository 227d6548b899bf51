#include "edm/hmi/web_manual.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "edm/hmi/manual.hpp"
#include "edm/hmi/work_offsets.hpp"

namespace edm::hmi {

namespace {

using bridge::Json;
using Clock = std::chrono::steady_clock;
constexpr auto kStatusPeriod = std::chrono::milliseconds(150);
constexpr auto kOffsetsPeriod = std::chrono::seconds(1);

Clock::duration ms(double v) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(v));
}

Json refused(std::string_view code, const std::string& message) {
  return {{"ok", false}, {"code", code}, {"message", message}};
}

std::optional<double> number(const Json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

}  // namespace

JogTiming jog_timing(double deadman_ms, double clock_rate) noexcept {
  if (!(clock_rate > 0.0) || !std::isfinite(clock_rate)) clock_rate = 1.0;
  if (!(deadman_ms > 0.0) || !std::isfinite(deadman_ms)) deadman_ms = 500.0;
  JogTiming t;
  t.deadman_ms = deadman_ms / clock_rate;
  t.refresh_ms = std::max(5.0, t.deadman_ms / 3.0);
  t.hold_window_ms = std::max(kMinHoldWindowMs, t.deadman_ms / 2.0);
  t.held_ms = t.hold_window_ms / 3.0;
  return t;
}

Json page_reply(const bridge::Reply& r) {
  Json j = {{"ok", r.ok}, {"body", r.body}};
  if (!r.ok) {
    j["code"] = r.code ? std::string(bridge::to_string(*r.code)) : "transport";
    j["message"] = r.message;
    if (!r.details.is_null()) j["details"] = r.details;
  }
  return j;
}

WebManual::~WebManual() { stop(); }

void WebManual::start(const Json& manual_info, bool has_manual_status, bool has_offsets) {
  {
    std::lock_guard lock(mutex_);
    if (const auto d = number(manual_info, "deadman_ms"); d && *d > 0.0) deadman_ms_ = *d;
    has_status_ = has_manual_status;
    has_offsets_ = has_offsets;
    offsets_stale_ = true;
    if (started_) return;  // edmplc again (restarted): the same thread follows it
    started_ = true;
  }
  thread_ = std::thread([this] {
    for (;;) {  // run() returns when stopping; an odd reply from edmplc never ends the process
      try {
        run();
        return;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "edmhmi serve: manual follower: %s\n", e.what());
      }
    }
  });
}

void WebManual::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  bool held = false;
  {
    std::lock_guard lock(mutex_);
    held = hold_.has_value() || stop_jog_;
    hold_.reset();
  }
  if (held) client_.request("jog.stop");
}

void WebManual::on_status_time(double t_s) {
  const auto now = Clock::now();
  std::lock_guard lock(mutex_);
  if (!rate_ref_) {
    rate_ref_.emplace(t_s, now);
    return;
  }
  const double real_s = std::chrono::duration<double>(now - rate_ref_->second).count();
  const double machine_s = t_s - rate_ref_->first;
  if (machine_s < 0.0 || real_s > 10.0) {  // edmplc restarted, or a long silence
    rate_ref_.emplace(t_s, now);
    return;
  }
  if (real_s >= 1.0) {
    if (machine_s > 0.0) rate_ = std::clamp(machine_s / real_s, 0.01, 1000.0);
    rate_ref_.emplace(t_s, now);
  }
}

double WebManual::clock_rate() const {
  std::lock_guard lock(mutex_);
  return rate_;
}

JogTiming WebManual::timing() const {
  std::lock_guard lock(mutex_);
  return jog_timing(deadman_ms_, rate_);
}

Json WebManual::hold(std::uint64_t owner, const std::string& axis, double velocity_mm_s) {
  {
    std::lock_guard lock(mutex_);
    pending_hold_ = owner;
    pending_released_ = false;
  }
  const bridge::Reply r = client_.request("jog", Json{{"axis", axis}, {"velocity", velocity_mm_s}});
  std::lock_guard lock(mutex_);
  const bool released = pending_released_ && pending_hold_ == owner;
  if (pending_hold_ == owner) pending_hold_.reset();
  if (!r) return page_reply(r);
  Json out = page_reply(r);
  const JogTiming t = jog_timing(deadman_ms_, rate_);
  out["body"]["held_ms"] = t.held_ms;
  out["body"]["refresh_ms"] = t.refresh_ms;
  if (released) {  // let go before edmplc answered
    stop_jog_ = true;
    out["body"]["released"] = true;
  } else {
    const auto now = Clock::now();
    hold_ = Hold{owner, axis, velocity_mm_s, now, now + ms(t.refresh_ms)};
    jog_error_ = nullptr;
  }
  cv_.notify_all();
  return out;
}

void WebManual::held(std::uint64_t owner) {
  std::lock_guard lock(mutex_);
  if (hold_ && hold_->owner == owner) hold_->last_held = Clock::now();
}

void WebManual::release(std::uint64_t owner) {
  {
    std::lock_guard lock(mutex_);
    if (pending_hold_ == owner) pending_released_ = true;
    if (!hold_ || hold_->owner != owner) return;
    hold_.reset();
    stop_jog_ = true;
  }
  cv_.notify_all();
}

void WebManual::release_any() {
  std::lock_guard lock(mutex_);
  if (pending_hold_) pending_released_ = true;
  hold_.reset();
}

Json WebManual::touch(const std::string& target, const std::string& set_frame) {
  if (!set_frame.empty() && !frame_index(set_frame)) {
    return refused("bad_request", "'set' must be one of G54 … G59");
  }
  const bridge::Reply r = client_.request("touch", Json{{"target", target}});
  if (r && !set_frame.empty()) {
    std::lock_guard lock(mutex_);
    touch_ = PendingTouch{r.body.value("seq", std::uint64_t{0}), target,
                          frame_name(*frame_index(set_frame))};
    touch_set_ = {{"frame", touch_->frame}, {"target", target}, {"pending", true}};
    next_status_ = Clock::now();
    manual_changed_ = true;
  }
  cv_.notify_all();
  return page_reply(r);
}

Json WebManual::offset_set(const Json& params) {
  const bridge::Reply r = client_.request("offset.set", params);
  if (r) {
    std::lock_guard lock(mutex_);
    offsets_stale_ = true;
  }
  cv_.notify_all();
  return page_reply(r);
}

Json WebManual::manual_json() const {
  std::lock_guard lock(mutex_);
  return manual_;
}

Json WebManual::offsets_json() const {
  std::lock_guard lock(mutex_);
  return offsets_;
}

WebManual::Changes WebManual::take_changes() {
  std::lock_guard lock(mutex_);
  Changes c;
  if (manual_changed_) c.manual = manual_;
  if (offsets_changed_) c.offsets = offsets_;
  manual_changed_ = offsets_changed_ = false;
  return c;
}

void WebManual::run() {
  for (;;) {
    enum class Jog { kNone, kStop, kRefresh } jog = Jog::kNone;
    Hold h;
    bool poll_status = false, poll_offsets = false;
    {
      std::unique_lock lock(mutex_);
      if (stopping_) return;
      const auto now = Clock::now();
      const JogTiming t = jog_timing(deadman_ms_, rate_);
      if (hold_ && now - hold_->last_held > ms(t.hold_window_ms)) {
        // The browser stopped saying "held": asleep, gone, or its network is.
        hold_.reset();
        stop_jog_ = true;
        jog_error_ = "no 'held' from the browser within " +
                     std::to_string(static_cast<int>(t.hold_window_ms)) + " ms: jog stopped";
        manual_changed_ = true;
      }
      if (stop_jog_) {
        jog = Jog::kStop;
        stop_jog_ = false;
      } else if (hold_ && now >= hold_->next_refresh) {
        jog = Jog::kRefresh;
        h = *hold_;
        hold_->next_refresh = now + ms(t.refresh_ms);
      }
      poll_status = has_status_ && now >= next_status_;
      poll_offsets = has_offsets_ && (offsets_stale_ || now >= next_offsets_);
      if (jog == Jog::kNone && !poll_status && !poll_offsets) {
        auto wake = now + std::chrono::seconds(1);
        if (has_status_) wake = std::min(wake, next_status_);
        if (has_offsets_) wake = std::min(wake, next_offsets_);
        if (hold_) {
          wake = std::min({wake, hold_->next_refresh, hold_->last_held + ms(t.hold_window_ms)});
        }
        cv_.wait_until(lock, wake);
        continue;
      }
    }
    // The jog first: a poll never delays a refresh or a stop.
    if (jog == Jog::kStop) {
      client_.request("jog.stop");
    } else if (jog == Jog::kRefresh) {
      const bridge::Reply r =
          client_.request("jog", Json{{"axis", h.axis}, {"velocity", h.velocity_mm_s}});
      if (!r) {  // E-stop, a job, a fault: the hold ends (edmplc has stopped the axis)
        std::lock_guard lock(mutex_);
        if (hold_ && hold_->owner == h.owner) hold_.reset();
        jog_error_ = "jog refused: " + page_reply(r).value("message", std::string());
        manual_changed_ = true;
      }
    }
    if (poll_status) follow_status();
    if (poll_offsets) follow_offsets();
  }
}

void WebManual::follow_status() {
  const bridge::Reply r = client_.request("manual.status");
  Json m = r ? r.body : Json{{"error", page_reply(r).value("message", std::string())}};
  m.erase("id");
  m.erase("ok");
  std::optional<PendingTouch> touch;
  {
    std::lock_guard lock(mutex_);
    next_status_ = Clock::now() + kStatusPeriod;
    touch = touch_;
  }
  // A touch to put into a work frame: once the runtime answered that very request.
  const Json* res = m.contains("result") && m["result"].is_object() ? &m["result"] : nullptr;
  if (touch && res != nullptr && res->value("seq", std::uint64_t{0}) >= touch->seq &&
      !m.value("busy", false)) {
    Json set = {{"frame", touch->frame}, {"target", touch->target}, {"pending", false}};
    if (res->value("seq", std::uint64_t{0}) != touch->seq) {
      set["ok"] = false;
      set["message"] = "another manual operation came first: " + touch->frame + " not set";
    } else if (!res->value("ok", false)) {
      set["ok"] = false;
      set["message"] = "touch " + touch->target + " failed (" +
                       res->value("error", std::string("?")) + "): " + touch->frame + " not set";
    } else {
      ManualResult result;
      result.ok = true;
      result.x_mm = number(*res, "x");
      result.y_mm = number(*res, "y");
      result.z_mm = number(*res, "z");
      const std::optional<TouchTarget> t = parse_touch_target(touch->target);
      const std::optional<Json> params =
          t ? offset_set_for_touch(touch->frame, *t, result) : std::nullopt;
      if (!params) {
        set["ok"] = false;
        set["message"] = "the touch result lacks a coordinate: " + touch->frame + " not set";
      } else {
        const bridge::Reply sr = client_.request("offset.set", *params);
        set["ok"] = sr.ok;
        for (const char* k : {"x", "y", "z"}) {
          if (params->contains(k)) set[k] = (*params)[k];
        }
        set["message"] =
            sr ? touch->frame + " set from touch " + touch->target
               : "offset.set refused: " + page_reply(sr).value("message", std::string());
      }
    }
    std::lock_guard lock(mutex_);
    if (touch_ && touch_->seq == touch->seq) touch_.reset();
    touch_set_ = std::move(set);
    offsets_stale_ = true;
  }
  std::lock_guard lock(mutex_);
  m["touch_set"] = touch_set_;
  m["jog"] = {{"held", hold_.has_value()},
              {"axis", hold_ ? Json(hold_->axis) : Json(nullptr)},
              {"velocity", hold_ ? Json(hold_->velocity_mm_s) : Json(nullptr)},
              {"error", jog_error_}};
  if (m != manual_) {
    manual_ = std::move(m);
    manual_changed_ = true;
  }
}

void WebManual::follow_offsets() {
  {
    std::lock_guard lock(mutex_);
    offsets_stale_ = false;
    next_offsets_ = Clock::now() + kOffsetsPeriod;
  }
  const bridge::Reply r = client_.request("offset.get");
  if (!r) return;
  Json o = {{"frames", r.body.value("frames", Json::object())},
            {"generation", r.body.value("generation", std::uint64_t{0})}};
  std::lock_guard lock(mutex_);
  if (o != offsets_) {
    offsets_ = std::move(o);
    offsets_changed_ = true;
  }
}

}  // namespace edm::hmi
