// The hub's link to edmplc: connect with back-off, set the session up, wait for it to go away,
// and say so to every socket meanwhile (web_hub.hpp).
#include <algorithm>
#include <array>
#include <boost/asio/post.hpp>
#include <cstdio>
#include <limits>
#include <string_view>

#include "edm/hmi/web_backoff.hpp"
#include "edm/hmi/web_capabilities.hpp"
#include "edm/hmi/web_hub.hpp"

namespace edm::hmi {

namespace {

using bridge::Json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The page's chart series and the variables that may feed them: an exact name, or "*suffix"
/// for the first pin whose name ends so (programs and blocks are named by each config).
struct SeriesWish {
  std::string_view key;
  std::array<std::string_view, 2> candidates;
};
constexpr std::array<SeriesWish, 12> kSeriesWishes{{
    {"z", {"io.z_mm", ""}},
    {"depth", {"io.depth_mm", ""}},
    {"depth_est", {"*.drill.depth_reached_mm", "*.depth_reached_mm"}},
    {"td", {"*.drill.td.td_us", "*.td.td_us"}},
    {"tdr", {"*.drill.tdr_us", "*.tdr_us"}},
    {"feed", {"*.drill.gap.vz_mm_s", "io.vz_cmd"}},
    {"short", {"io.ratio_short", ""}},
    {"arc_t", {"io.ratio_transient_arc", ""}},
    {"arc_s", {"io.ratio_stable_arc", ""}},
    {"x", {"io.x_mm", ""}},
    {"y", {"io.y_mm", ""}},
    // Not drawn: the feed override as the machine runs it (EdmJob drives it into the drill every
    // cycle from the operator's value), the page's readback beside its control.
    {"override", {"*.drill.feed_override", "*.feed_override"}},
}};

bool matches(std::string_view name, std::string_view wish) {
  if (wish.empty()) return false;
  if (wish.front() == '*') return name.ends_with(wish.substr(1));
  return name == wish;
}

std::string string_field(const Json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

/// Picks each series' variable among the pins of one task (the task of io.z_mm, else the first
/// matching pin's), so one trace event carries a whole row.
std::vector<WebSeries> choose_series(const Json& var_list) {
  struct Pin {
    std::string name, task;
  };
  std::vector<Pin> pins;
  if (var_list.contains("vars") && var_list["vars"].is_array()) {
    for (const Json& v : var_list["vars"]) {
      if (!v.is_object()) continue;
      const std::string kind = string_field(v, "kind");
      if (kind != "input" && kind != "output") continue;
      pins.push_back({string_field(v, "name"), string_field(v, "task")});
    }
  }
  std::string task;
  for (const Pin& p : pins) {
    if (p.name == "io.z_mm") task = p.task;
  }
  std::vector<WebSeries> out;
  for (const SeriesWish& w : kSeriesWishes) {
    for (std::string_view c : w.candidates) {
      const auto it = std::find_if(pins.begin(), pins.end(), [&](const Pin& p) {
        return matches(p.name, c) && (task.empty() || p.task == task);
      });
      if (it != pins.end()) {
        if (task.empty()) task = it->task;
        out.push_back({std::string(w.key), it->name});
        break;
      }
    }
  }
  return out;
}

}  // namespace

void WebHub::start() {
  client_.set_event_handler([this](const Json& ev) {
    try {
      on_event(ev);
    } catch (const std::exception& e) {  // an odd event is dropped, never fatal
      std::fprintf(stderr, "edmhmi serve: event dropped: %s\n", e.what());
    }
  });
  client_.set_connection_handler([this](bool up) {
    {
      std::lock_guard lock(mutex_);
      if (!up) lost_ = true;
    }
    if (!up) link_cv_.notify_all();
  });
  arm_timer();
  link_thread_ = std::thread([this] { link_loop(); });
}

void WebHub::set_bridge_state(bool up, std::string message) {
  std::string text = Json{{"t", "bridge"}, {"up", up}, {"message", std::move(message)}}.dump(
      -1, ' ', false, Json::error_handler_t::replace);
  {
    std::lock_guard lock(mutex_);
    if (bridge_up_ != up) bridge_changed_ = true;
    bridge_up_ = up;
    ready_ = up;
    if (text == bridge_text_) return;
    bridge_text_ = text;
  }
  boost::asio::post(ioc_, [this, text = std::move(text), alive = alive_token()] {
    if (!alive.expired()) broadcast_all(text);
  });
}

void WebHub::link_loop() {
  const std::string where = settings_.host + ":" + std::to_string(settings_.port);
  Backoff backoff(kReconnectFirst, kReconnectMax);
  std::string last_why;
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (link_stopping_) return;
      lost_ = false;
    }
    std::string why;
    try {
      bridge::ClientOptions o = client_options(settings_);
      o.auto_reconnect = false;  // this loop reconnects, and sets the session up again
      client_.connect(o);
      set_up_session();
    } catch (const std::exception& e) {
      why = e.what();
    }
    if (why.empty()) {
      {
        std::lock_guard lock(mutex_);
        ++counters_.bridge_connects;
      }
      backoff.succeed();
      last_why.clear();
      std::printf("edmhmi serve: connected to edmplc at %s as %s\n", where.c_str(),
                  std::string(bridge::to_string(client_.role())).c_str());
      std::fflush(stdout);
      set_bridge_state(true, "edmplc at " + where);
      std::unique_lock lock(mutex_);
      link_cv_.wait(lock, [this] { return link_stopping_ || lost_ || !client_.connected(); });
      if (link_stopping_) return;
      lock.unlock();
      why = "the connection was lost";
    }
    client_.close();
    set_bridge_state(false, "waiting for edmplc at " + where + " (" + why + ")");
    if (why != last_why) {  // once per cause, not once per try
      std::fprintf(stderr, "edmhmi serve: waiting for edmplc at %s: %s\n", where.c_str(),
                   why.c_str());
      last_why = why;
    }
    const auto delay = backoff.fail();
    std::unique_lock lock(mutex_);
    if (link_cv_.wait_for(lock, delay, [this] { return link_stopping_; })) return;
  }
}

void WebHub::set_up_session() {
  std::string error;
  if (!job_.refresh_machine(error)) throw bridge::ClientError(error);
  const Json info = job_.machine_info_raw();
  Json caps;
  if (info.contains("ops")) {
    caps = capabilities_json(info, nullptr);
  } else {  // an edmplc before issue 21
    try {
      const std::vector<std::string> known = probe_ops(
          settings_.host, settings_.port, operator_function_ops(), std::chrono::seconds(3));
      caps = capabilities_json(info, &known);
    } catch (const std::exception& e) {
      caps = capabilities_json(info, nullptr);
      caps["error"] = e.what();
    }
  }
  if (std::string why; !job_.refresh_offsets(why)) throw bridge::ClientError(why);
  const bridge::Reply vars = client_.request("var.list");
  if (!vars) throw bridge::ClientError("var.list: " + vars.message, vars.code);
  std::vector<WebSeries> series = choose_series(vars.body);
  const Json manual_info = caps.value("manual", Json(nullptr));
  const bool has_manual_status = caps.contains("manual_status") && caps["manual_status"] == true;
  const bool has_offsets = caps.contains("work_coordinates") && caps["work_coordinates"] == true;
  {
    std::lock_guard lock(mutex_);
    caps_ = std::move(caps);
    if (series.size() != series_.size() ||
        !std::equal(series.begin(), series.end(), series_.begin(),
                    [](const WebSeries& a, const WebSeries& b) { return a.var == b.var; })) {
      row_.assign(series.size(), kNaN);
    }
    series_ = series;
    last_row_t_ = -1.0;  // a restarted edmplc's clock begins again
  }
  if (const bridge::Reply r = client_.subscribe({"status", "alarm", "progress"}, kFrameHz); !r) {
    throw bridge::ClientError("subscribe: " + r.message, r.code);
  }
  manual_.start(manual_info, has_manual_status, has_offsets);
  if (!series.empty()) {
    std::vector<std::string> names;
    for (const WebSeries& s : series) names.push_back(s.var);
    if (const bridge::Reply r = client_.trace_start(names); !r) {
      throw bridge::ClientError("trace.start: " + r.message, r.code);
    }
  }
}

}  // namespace edm::hmi
